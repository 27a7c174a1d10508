// Copies of a generated block of tests inside SQLite, for `eol db-bench --replicate K`: a store
// of millions of tests written at the disk's speed instead of the Store's (issue 16, "per-serial
// queries and exports measured on a database of 5 million tests").
//
// The block is tests 1..block_tests as a fresh store numbered them (checked), with units
// DbBenchSerial(1 .. block_units). Copy k = 1 .. copies-1 gets ids shifted by k * block_tests,
// serials by k * block_units (DbBenchSerial(u + k * block_units)), times by k *
// block_span_s, and the same record, reasons, measurement rows, curves and outbox entries:
// the same bytes per test and the same indexes as a generated store; only the values repeat
// from copy to copy (nothing in SQLite compresses, so sizes and query costs are those of
// distinct values). Each copy is one transaction. Throws std::runtime_error naming the step.
#pragma once

#include <cstdint>
#include <string>

#include "analysis/progress.h"

namespace eol::station {

// db-bench's serial of unit u: "DBB-" and u in 9 digits (DBB-000000001); the one format both
// the generator and the copies write.
inline constexpr const char* kDbBenchSerialPrefix = "DBB-";
inline constexpr int kDbBenchSerialDigits = 9;
std::string DbBenchSerial(std::int64_t unit);

void ReplicateBlock(const std::string& db_path, std::int64_t block_tests, std::int64_t block_units,
                    double block_span_s, int copies, const analysis::ProgressCallback& progress);

}  // namespace eol::station
