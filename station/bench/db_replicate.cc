#include "station/bench/db_replicate.h"

#include <sqlite3.h>

#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <stdexcept>

#include "db/test_columns.h"

namespace eol::station {
namespace {

using Db = std::unique_ptr<sqlite3, decltype(&sqlite3_close)>;

Db OpenForWrite(const std::string& path) {
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(path.c_str(), &raw, SQLITE_OPEN_READWRITE, nullptr);
  Db db(raw, &sqlite3_close);
  if (rc != SQLITE_OK)
    throw std::runtime_error(
        path + ": open for replication: " + (raw ? sqlite3_errmsg(raw) : sqlite3_errstr(rc)));
  return db;
}

void Exec(sqlite3* db, const std::string& path, const std::string& sql, const std::string& step) {
  char* error = nullptr;
  if (sqlite3_exec(db, sql.c_str(), nullptr, nullptr, &error) != SQLITE_OK) {
    const std::string why = error ? error : sqlite3_errmsg(db);
    sqlite3_free(error);
    throw std::runtime_error(path + ": " + step + ": " + why);
  }
}

std::int64_t Count(sqlite3* db, const std::string& path, const char* sql) {
  sqlite3_stmt* raw = nullptr;
  if (sqlite3_prepare_v2(db, sql, -1, &raw, nullptr) != SQLITE_OK)
    throw std::runtime_error(path + ": " + sql + ": " + sqlite3_errmsg(db));
  std::unique_ptr<sqlite3_stmt, decltype(&sqlite3_finalize)> s(raw, &sqlite3_finalize);
  if (sqlite3_step(raw) != SQLITE_ROW)
    throw std::runtime_error(path + ": " + sql + ": " + sqlite3_errmsg(db));
  return sqlite3_column_int64(raw, 0);
}

// `sql` with every {NAME} replaced by its number.
std::string Fill(std::string sql, const std::map<std::string, std::string>& values) {
  for (const auto& [name, value] : values)
    for (std::size_t at; (at = sql.find("{" + name + "}")) != std::string::npos;)
      sql.replace(at, name.size() + 2, value);
  return sql;
}

// Copy k of the measurements, curves and outbox rows of tests 1..{N}.
constexpr const char* kCopyRowsSql =
    "INSERT INTO measurements (test_id, name, value, sigma, unit, lo, hi, outcome, marginal) "
    "SELECT test_id + {SHIFT}, name, value, sigma, unit, lo, hi, outcome, marginal "
    "FROM measurements WHERE test_id <= {N};"
    "INSERT INTO curves (test_id, name, raw_size, data, encoding) "
    "SELECT test_id + {SHIFT}, name, raw_size, data, encoding FROM curves WHERE test_id <= {N};"
    "INSERT INTO outbox (test_id, created_at) "
    "SELECT test_id + {SHIFT}, created_at FROM outbox WHERE test_id <= {N};";

// How copy k changes a column of the tests table: ids + {SHIFT}, units + {UNITS}, times +
// {LATER} seconds; every other column (db/test_columns.h) is copied as it is.
const std::map<std::string, std::string> kShiftedTestColumns = {
    {"id", "id + {SHIFT}"},
    {"serial",
     "'{PREFIX}' || printf('%0{DIGITS}d', CAST(substr(serial, {FROM}) AS INTEGER) + {UNITS})"},
    {"started_at", "strftime('%Y-%m-%dT%H:%M:%fZ', started_at, '+{LATER} seconds')"},
    {"finished_at", "strftime('%Y-%m-%dT%H:%M:%fZ', finished_at, '+{LATER} seconds')"},
    {"retest_of", "retest_of + {SHIFT}"}};

// Copy k of tests 1..{N} with their measurements, curves and outbox rows.
std::string CopySql() {
  std::string names, values;
  std::size_t found = 0;
  for (const db::TestColumn& c : db::TestColumns()) {
    if (c.store == db::StoreWrite::kNone) continue;
    const auto shifted = kShiftedTestColumns.find(c.name);
    found += shifted != kShiftedTestColumns.end() ? 1 : 0;
    names += (names.empty() ? "" : ", ") + std::string(c.name);
    values += (values.empty() ? "" : ", ") +
              (shifted != kShiftedTestColumns.end() ? shifted->second : std::string(c.name));
  }
  if (found != kShiftedTestColumns.size())
    throw std::logic_error("db-bench replication shifts a column the tests table does not have");
  return "INSERT INTO tests (" + names + ") SELECT " + values + " FROM tests WHERE id <= {N};" +
         kCopyRowsSql;
}

}  // namespace

std::string DbBenchSerial(std::int64_t unit) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s%0*lld", kDbBenchSerialPrefix, kDbBenchSerialDigits,
                static_cast<long long>(unit));
  return buf;
}

void ReplicateBlock(const std::string& path, std::int64_t block_tests, std::int64_t block_units,
                    double block_span_s, int copies, const analysis::ProgressCallback& progress) {
  if (copies <= 1) return;
  Db db = OpenForWrite(path);
  sqlite3_busy_timeout(db.get(), 5000);
  if (Count(db.get(), path, "SELECT count(*) FROM tests") != block_tests ||
      Count(db.get(), path, "SELECT min(id) FROM tests") != 1 ||
      Count(db.get(), path, "SELECT max(id) FROM tests") != block_tests)
    throw std::runtime_error(path + ": replication needs a fresh store of tests 1.." +
                             std::to_string(block_tests));
  for (int k = 1; k < copies; ++k) {
    char later[64];
    std::snprintf(later, sizeof later, "%.3f", k * block_span_s);
    const std::string sql =
        Fill(CopySql(), {{"N", std::to_string(block_tests)},
                         {"SHIFT", std::to_string(k * block_tests)},
                         {"UNITS", std::to_string(k * block_units)},
                         {"LATER", later},
                         {"PREFIX", kDbBenchSerialPrefix},
                         {"DIGITS", std::to_string(kDbBenchSerialDigits)},
                         {"FROM", std::to_string(std::strlen(kDbBenchSerialPrefix) + 1)}});
    Exec(db.get(), path, "BEGIN IMMEDIATE", "begin copy");
    try {
      Exec(db.get(), path, sql, "copy " + std::to_string(k));
      Exec(db.get(), path, "COMMIT", "commit copy");
    } catch (...) {
      sqlite3_exec(db.get(), "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
    if (progress) progress("replicate", k + 1, copies);
  }
  if (Count(db.get(), path, "SELECT count(*) FROM tests") != block_tests * copies)
    throw std::runtime_error(path + ": replication left a wrong number of tests");
}

}  // namespace eol::station
