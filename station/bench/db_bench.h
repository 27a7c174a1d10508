// `eol db-bench`: the store at a production line's scale (issue 16, "records that scale").
//
// Generates a store of `tests` tests from a template record (the newest test of a station
// store, with its curves: what the station really writes), one test per `interval_s` of a
// line from 2026-01-01, a share of them retests of the previous serial, each with its
// measurements and curve values perturbed (so nothing compresses better than real data), in
// transactions of `batch` tests (Store::InsertAll). Then, on that file, through the same Store
// calls `eol query` and `eol export` make:
//   - the history of a serial (TestsOfSerial) and its newest test with curves
//     (LatestOfSerial) for `queries` random serials: median and 99th percentile latency;
//   - the export of one day of tests (Tests, keyset pages of 10,000, with and without curves)
//     and of one day's measurement rows (MeasurementRows): rows per second;
// and the file's size: bytes per test and the growth per year at the line's rate. Last, what
// the store's guards cost at that size: opening it (PRAGMA quick_check, read-only
// and as the station's writer) and finishing a test as the station does (BeginTest +
// FinishTest, one at a time), with and without the checkpoint after each verdict; these
// `finish_samples` x 2 tests ("GUARD-...") are added after every other figure is taken, then
// removed (with the last-verdict file that names one of them).
// With replicate K > 1 the generated block is then copied K - 1 times inside SQLite
// (db_replicate.h: later in time, new serials, the same bytes), so a store of tests x K is
// measured without generating each test through the Store.
// Progress goes to `progress` (analysis/progress.h).
#pragma once

#include <cstdint>
#include <string>

#include "analysis/progress.h"

namespace eol::station {

struct DbBenchOptions {
  std::string db;           // created; must not exist
  std::string template_db;  // a station store with at least one finished test
  std::int64_t tests = 100000;
  int batch = 10000;
  double interval_s = 10.0;    // one test per interval on the simulated line
  double retest_share = 0.03;  // tests that repeat the previous serial
  int queries = 1000;          // random serials looked up
  std::uint64_t seed = 1;
  int replicate = 1;        // copies of the generated block in the store (1: the block alone)
  int finish_samples = 50;  // tests finished one at a time, each way
  analysis::ProgressCallback progress;
};

struct DbBenchSummary {
  std::int64_t tests = 0;      // in the store: generated x replicate
  std::int64_t generated = 0;  // generated through the Store
  double insert_s = 0.0;       // wall time of the generation
  double replicate_s = 0.0;    // wall time of the copies
  double file_bytes = 0.0;     // database + WAL after a checkpoint
  double bytes_per_test = 0.0;
  double growth_gb_per_year = 0.0;                       // at one test per interval_s, all year
  double history_median_ms = 0.0, history_p99_ms = 0.0;  // TestsOfSerial
  double latest_median_ms = 0.0, latest_p99_ms = 0.0;    // LatestOfSerial (with curves)
  std::int64_t day_tests = 0;
  double day_export_s = 0.0;         // one day's tests, no curves
  double day_export_curves_s = 0.0;  // the same with curves
  std::int64_t day_measurement_rows = 0;
  double day_measurements_s = 0.0;
  std::string template_serial;    // whose record was the template
  double open_read_only_s = 0.0;  // Store::Open kReadOnly (quick_check): eol query, eol export
  double open_writer_s = 0.0;     // Store::Open kWriter (quick_check, checks): the station
  double finish_median_ms = 0.0, finish_p99_ms = 0.0;  // BeginTest + FinishTest, checkpointed
  double finish_no_checkpoint_median_ms = 0.0, finish_no_checkpoint_p99_ms = 0.0;
};

// Throws std::runtime_error (or db::StoreError) naming the cause.
DbBenchSummary RunDbBench(const DbBenchOptions& options);

}  // namespace eol::station
