#include "db/store_checks.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "db/schema.h"
#include "db/sqlite_statement.h"

namespace eol::db::internal {
namespace {

namespace fs = std::filesystem;

constexpr std::size_t kHeaderBytes = 100;     // SQLite's database header
constexpr char kMagic[] = "SQLite format 3";  // with its NUL: the first 16 bytes
constexpr int kQuickCheckRows = 10;           // problems named at most

// How a refused file is left, and what a person does about it.
constexpr const char* kUntouched = "; the file is left as it is and nothing was created beside it";

std::uint32_t BigEndian32(const unsigned char* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

// The first bytes as text an operator can recognise ("root:x:0:0:...").
std::string Printable(const unsigned char* p, std::size_t n) {
  std::string out;
  for (std::size_t i = 0; i < n && i < 24; ++i)
    out += (p[i] >= 0x20 && p[i] < 0x7f) ? static_cast<char>(p[i]) : '.';
  return out;
}

void CheckHeader(const std::string& path, std::uintmax_t size) {
  std::array<unsigned char, kHeaderBytes> h{};
  std::ifstream in(path, std::ios::binary);
  in.read(reinterpret_cast<char*>(h.data()), h.size());
  const auto n = static_cast<std::size_t>(in.gcount());
  if (!in && !in.eof()) throw StoreError(Message(path, "open", "cannot read the file"));
  if (n < sizeof kMagic || std::memcmp(h.data(), kMagic, sizeof kMagic) != 0)
    throw StoreRefused(Message(path, "open",
                               "not a database (" + std::to_string(size) + " bytes beginning \"" +
                                   Printable(h.data(), n) +
                                   "\", not SQLite's header), so not a store" + kUntouched));
  // The header may lag behind the WAL, but never holds another application's id.
  const std::uint32_t app_id = n >= 72 ? BigEndian32(h.data() + 68) : 0;
  if (app_id != 0 && app_id != static_cast<std::uint32_t>(schema::kApplicationId))
    throw StoreRefused(Message(path, "open",
                               "not an EOL test store (an SQLite database with application_id " +
                                   std::to_string(app_id) + ")" + kUntouched));
}

}  // namespace

FileState CheckFile(const std::string& path, Store::Role role, const OpenOptions& options) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st)) {
    // sqlite3_open_v2 would name a missing file "unable to open database file".
    if (role == Store::Role::kReadOnly)
      throw StoreError(Message(path, "open read-only", "no such file"));
    std::string problem;
    const std::optional<LastVerdict> acked = ReadLastVerdict(LastVerdictPath(path), &problem);
    if (acked && !options.create_if_empty)
      throw StoreRefused(
          Message(path, "open",
                  "no such file, but " + LastVerdictPath(path) + " says test " +
                      std::to_string(acked->test_id) + " (" + acked->outcome + ", serial " +
                      acked->serial + ") was stored here at " + acked->finished_at +
                      ": the store was deleted or moved; restore it, or start with --init-store to "
                      "begin a new store (new tests are numbered after that one)"));
    return FileState::kMissing;
  }
  if (!fs::is_regular_file(st))
    throw StoreRefused(
        Message(path, "open", "not a regular file, so not a store" + std::string(kUntouched)));
  const std::uintmax_t size = fs::file_size(path, ec);
  if (ec) throw StoreError(Message(path, "open", "cannot read its size: " + ec.message()));
  if (size == 0) {
    if (options.create_if_empty && role != Store::Role::kReadOnly) return FileState::kEmpty;
    throw StoreRefused(
        Message(path, "open",
                "the file is empty (0 bytes): not an EOL test store (truncated or replaced?)" +
                    std::string(kUntouched) + "; " +
                    (role == Store::Role::kReadOnly ? "nothing to read" : kInitStoreHint)));
  }
  CheckHeader(path, size);
  return FileState::kHasBytes;
}

namespace {

// Interrupts `db` (sqlite3_interrupt) once `budget_ms` have passed, unless destroyed first.
class Deadline {
 public:
  Deadline(sqlite3* db, int budget_ms)
      : thread_([this, db, budget_ms] {
          std::unique_lock<std::mutex> lock(mu_);
          if (!cv_.wait_for(lock, std::chrono::milliseconds(budget_ms), [this] { return done_; }))
            sqlite3_interrupt(db);
        }) {}
  ~Deadline() {
    {
      std::lock_guard<std::mutex> lock(mu_);
      done_ = true;
    }
    cv_.notify_all();
    thread_.join();
  }
  Deadline(const Deadline&) = delete;
  Deadline& operator=(const Deadline&) = delete;

 private:
  std::mutex mu_;
  std::condition_variable cv_;
  bool done_ = false;
  std::thread thread_;  // last: started once the members above exist
};

}  // namespace

std::string QuickCheck(sqlite3* db, const std::string& path, int budget_ms) {
  const std::string op = "open (PRAGMA quick_check)";
  if (budget_ms == 0) return "PRAGMA quick_check not run (its budget is 0 s)";
  Statement s(db, path, "PRAGMA quick_check(" + std::to_string(kQuickCheckRows) + ")", op);
  std::string problems;
  const auto start = std::chrono::steady_clock::now();
  try {
    Deadline deadline(db, budget_ms);
    while (s.Step()) {
      std::string row = s.Text(0);
      if (row == "ok") return "";
      constexpr std::string_view kHeading = "*** in database main ***\n";
      if (row.starts_with(kHeading)) row.erase(0, kHeading.size());
      std::replace(row.begin(), row.end(), '\n', ' ');
      problems += (problems.empty() ? "" : "; ") + row;
    }
  } catch (const StoreError&) {
    if (problems.empty() && (sqlite3_errcode(db) & 0xff) == SQLITE_INTERRUPT) {
      const double s_used =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      std::error_code ec;
      const double gb = static_cast<double>(fs::file_size(path, ec)) / 1e9;
      char text[160];
      std::snprintf(text, sizeof text,
                    "PRAGMA quick_check stopped after its budget of %.1f s (%.1f s) on %.2f GB: "
                    "the file was not checked to its end",
                    budget_ms / 1e3, s_used, gb);
      return text;
    }
    // SQLite stops the check at a page it cannot read, after naming what it found.
    if (problems.empty()) throw;
    problems += "; then " + std::string(sqlite3_errmsg(db));
  }
  throw StoreRefused(Message(
      path, op,
      "the store is damaged: " + problems +
          "; it is not used: keep the file (and its -wal) for analysis, then restore a backup "
          "or move the file aside and start a new store"));
}

std::string FindLostVerdict(sqlite3* db, const std::string& path, const LastVerdict& acked) {
  const std::string op = "open (compare with " + LastVerdictPath(path) + ")";
  const std::string what = "test " + std::to_string(acked.test_id) + " (" + acked.outcome +
                           ", serial " + acked.serial + ") was acknowledged at " +
                           acked.finished_at;
  std::string stored;
  {
    Statement s(db, path, "SELECT outcome FROM tests WHERE id = ?1", op);
    s.BindInt(1, acked.test_id);
    if (s.Step()) stored = s.Text(0);
  }
  if (stored == acked.outcome) return "";
  if (!stored.empty())
    return what + ", but the store holds it as " + stored +
           ": its verdict is lost (a deleted or damaged WAL, or an older copy of the file)";
  const std::int64_t newest =
      PragmaInt(db, path, "SELECT coalesce(max(id), 0) FROM tests", op + " (newest test)");
  const std::string range = newest + 1 < acked.test_id ? "tests " + std::to_string(newest + 1) +
                                                             " to " + std::to_string(acked.test_id)
                                                       : "test " + std::to_string(acked.test_id);
  return "the store ends at test " + std::to_string(newest) + ", but " + what +
         ": the records of " + range +
         " are lost (a deleted or damaged WAL, or an older copy of the file); new tests are "
         "numbered from " +
         std::to_string(acked.test_id + 1);
}

std::vector<std::string> FindLostDeliveries(sqlite3* db, const std::string& path) {
  const std::string op = "open (compare the outbox cursors with the outbox)";
  Statement s(db, path,
              "SELECT consumer, last_id, (SELECT coalesce(max(id), 0) FROM outbox) "
              "FROM outbox_cursors WHERE last_id > (SELECT coalesce(max(id), 0) FROM outbox) "
              "ORDER BY consumer",
              op);
  std::vector<std::string> out;
  while (s.Step())
    out.push_back("the '" + s.Text(0) + "' publisher delivered outbox row " +
                  std::to_string(s.Int(1)) + ", but the outbox ends at row " +
                  std::to_string(s.Int(2)) + ": records it delivered are not in the store");
  return out;
}

}  // namespace eol::db::internal
