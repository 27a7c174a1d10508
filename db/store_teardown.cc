// Teardown findings (schema v7, db/schema.h kSchemaV7): recording and reading them.
#include <sqlite3.h>

#include <stdexcept>

#include "db/sqlite_statement.h"
#include "db/store.h"

namespace eol::db {
namespace {

using internal::Message;
using internal::Statement;
using internal::Transaction;

const char* StoredName(TeardownFinding f) {
  return f == TeardownFinding::kDefective ? "defective" : "not_defective";
}

bool Blank(const std::string& s) { return s.find_first_not_of(" \t\r\n") == std::string::npos; }

constexpr const char* kSelectTeardowns =
    "SELECT id, serial, found, note, by, at, test_id, corrects FROM teardowns ";

TeardownEntry RowToTeardown(const Statement& s, const std::string& path) {
  TeardownEntry e;
  e.id = s.Int(0);
  e.serial = s.Text(1);
  const std::optional<TeardownFinding> found = ParseTeardownFinding(s.Text(2));
  if (!found)
    throw StoreError(Message(path, "read teardown finding " + std::to_string(e.id),
                             "unknown finding '" + s.Text(2) + "'"));
  e.found = *found;
  e.note = s.Text(3);
  e.by = s.Text(4);
  e.at = s.Text(5);
  e.test_id = s.OptInt(6);
  e.corrects = s.OptInt(7);
  return e;
}

// The serial's newest finished (or aborted) test, and its newest finding.
std::optional<std::int64_t> NewestId(sqlite3* db, const std::string& path, const char* sql,
                                     const std::string& serial, const std::string& op) {
  Statement s(db, path, sql, op);
  s.BindText(1, serial);
  if (!s.Step()) return std::nullopt;
  return s.Int(0);
}

}  // namespace

const char* ToString(TeardownFinding f) {
  return f == TeardownFinding::kDefective ? "defective" : "not-defective";
}

std::optional<TeardownFinding> ParseTeardownFinding(std::string_view text) {
  if (text == "defective") return TeardownFinding::kDefective;
  if (text == "not-defective" || text == "not_defective") return TeardownFinding::kNotDefective;
  return std::nullopt;
}

TeardownEntry Store::AppendTeardown(const TeardownEntry& entry) {
  if (Blank(entry.serial)) throw std::invalid_argument("teardown finding: the serial is empty");
  if (Blank(entry.by))
    throw std::invalid_argument("teardown finding of " + entry.serial +
                                ": the engineer's name is empty");
  if (Blank(entry.at))
    throw std::invalid_argument("teardown finding of " + entry.serial + ": the time is empty");
  const std::string op = "record the teardown finding of " + entry.serial;
  TeardownEntry out = entry;
  try {
    FinishFailedWrites();
    Transaction tx(db_, path_, op);
    out.test_id = NewestId(db_, path_,
                           "SELECT id FROM tests WHERE serial = ?1 AND outcome <> 'RUNNING' "
                           "ORDER BY started_at DESC, id DESC LIMIT 1",
                           entry.serial, op);
    if (!out.test_id)
      throw std::invalid_argument("teardown finding of " + entry.serial +
                                  ": this store has no finished test of that serial (" + path_ +
                                  ")");
    out.corrects =
        NewestId(db_, path_, "SELECT max(id) FROM teardowns WHERE serial = ?1", entry.serial, op);
    if (out.corrects && *out.corrects == 0) out.corrects.reset();
    Statement s(db_, path_,
                "INSERT INTO teardowns (serial, found, note, by, at, test_id, corrects) "
                "VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
                op);
    s.BindText(1, entry.serial);
    s.BindText(2, StoredName(entry.found));
    s.BindText(3, entry.note);
    s.BindText(4, entry.by);
    s.BindText(5, entry.at);
    s.BindInt(6, *out.test_id);
    if (out.corrects)
      s.BindInt(7, *out.corrects);
    else
      s.BindNull(7);
    s.Run();
    out.id = sqlite3_last_insert_rowid(db_);
    tx.Commit();
  } catch (const StoreError& e) {
    Failed(e);
    throw;
  }
  write_failure_.clear();
  return out;
}

std::vector<TeardownEntry> Store::TeardownsOfSerial(const std::string& serial) {
  Statement s(db_, path_, std::string(kSelectTeardowns) + "WHERE serial = ?1 ORDER BY id",
              "read the teardown findings of " + serial);
  s.BindText(1, serial);
  std::vector<TeardownEntry> out;
  while (s.Step()) out.push_back(RowToTeardown(s, path_));
  return out;
}

std::vector<TeardownEntry> Store::CurrentTeardowns() {
  Statement s(db_, path_,
              std::string(kSelectTeardowns) +
                  "WHERE id IN (SELECT max(id) FROM teardowns GROUP BY serial) ORDER BY serial",
              "read the current teardown findings");
  std::vector<TeardownEntry> out;
  while (s.Step()) out.push_back(RowToTeardown(s, path_));
  return out;
}

}  // namespace eol::db
