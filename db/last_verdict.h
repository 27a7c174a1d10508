// The newest acknowledged verdict, kept outside the store in "<store>.last-verdict".
//
// A store cannot vouch for itself: a WAL deleted or damaged after a crash takes its newest
// commits with it, and SQLite opens the older state without a word. So once a verdict is
// durable (Store::FinishTest) the writer notes its test id and outcome here, fdatasync'ed,
// and the next Store::Open compares: a store whose newest test is older, or whose row of that
// test does not hold that outcome, has lost verdicts, and says which.
//
// The file: two slots of kLastVerdictSlotBytes, each one line of text padded with spaces,
//   eol-last-verdict 1 test=44 outcome=PASS finished=2026-11-28T21:40:00.000Z serial=M-7 crc=...
// (crc: 8 hex digits of the CRC-32 of the line before " crc="); the id's parity picks the
// slot, so a write torn by a power cut spoils only its own slot and the other still holds the
// previous verdict. The serial is cut to 64 bytes, control characters become '?' (the file
// names the test; the store holds it).
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace eol::db {

inline constexpr int kLastVerdictSlotBytes = 256;

struct LastVerdict {
  std::int64_t test_id = 0;
  std::string outcome;      // "PASS", "FAIL", "ERROR", "ABORTED"
  std::string finished_at;  // ISO 8601 UTC
  std::string serial;
};

// "<store path>.last-verdict".
std::string LastVerdictPath(const std::string& store_path);

// The newest valid slot of the file at `path`; nullopt when the file is missing or empty.
// A file with bytes but no valid slot sets `*problem` (and returns nullopt).
std::optional<LastVerdict> ReadLastVerdict(const std::string& path, std::string* problem);

// Writes `v` into its slot of the open file `fd` and fdatasyncs it. Returns "" or the
// failure (errno's text).
std::string WriteLastVerdict(int fd, const LastVerdict& v);

}  // namespace eol::db
