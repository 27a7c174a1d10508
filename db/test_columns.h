// The one list of a test's columns: every place that writes or reads a test as a row of columns
// is derived from it, so a new column is one entry here.
//
// Derived from it: the store's INSERT at BeginTest, its UPDATE at FinishTest, its SELECT and
// row reader of the tests table, the column lists and parsing of its yield and statistics
// readers (db/store_columns.h); the export's base columns (db/export_schema.h: its `meaning` is
// `doc`); the plant's central INSERT (station/daemon/central/central_record.cc); db-bench's copy of
// the tests table (station/bench/db_replicate.cc).
//
// Not derived, so a new column also needs: the field in TestRecord and its JSON
// (db/test_record.h), a new migration step of the store's schema (db/schema.h: ALTER TABLE
// tests ADD COLUMN) and, when replicated, the central schema
// (station/daemon/central/central_schema.h). tests/db/test_columns_test.cc checks this list against
// the tests table of a real store file (PRAGMA table_info) and round-trips every stored column;
// tests/station/central_record_test.cc checks it against the central table of a real PostgreSQL.
// The export's stability promise (db/export_schema.h) holds for the exported entries: an entry's
// export name, type and doc never change, and a new exported entry comes after every column of the
// current export schema version (export_since).
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <variant>

#include "db/export_schema.h"
#include "db/test_record.h"

namespace eol::db {

// One cell: NULL, an integer, text, or JSON (stored as its text; jsonb centrally).
using ColumnValue = std::variant<std::monostate, std::int64_t, std::string, nlohmann::json>;

// How the store's tests table gets a column.
enum class StoreWrite {
  kNone,      // not a column of the store's table (derived from others, e.g. reason_code)
  kByStore,   // assigned by the store at BeginTest (id, retest_of), not taken from the record
  kAtBegin,   // from the record at BeginTest
  kAtFinish,  // from the record at FinishTest (outcome is 'RUNNING' until then)
};

struct TestColumn {
  // The store's column and the export's (top-level JSON key, CSV header).
  const char* name;
  StoreWrite store;
  // Its type in the store's table as PRAGMA table_info says it: "INTEGER" (read as an
  // integer, NULL as empty) or "TEXT" (read as text, NULL as empty); "" when kNone.
  const char* sql_type;
  // The central table's column and its type as a PostgreSQL cast ("bigint", "integer", "text",
  // "timestamptz": empty text is NULL, "jsonb"); nullptr: not replicated as a column.
  const char* central_name;
  const char* central_type;
  // The export schema version that added the column to the export; 0: not exported.
  int export_since;
  ExportType export_type;
  const char* unit;  // of the exported value; "" for none
  // What the column holds: the export's meaning, and this column's documentation.
  const char* doc;
  ColumnValue (*get)(const TestRecord&);
  // Sets the record's field from the store's cell; nullptr when StoreWrite::kNone. Throws
  // std::invalid_argument naming the value (an unknown outcome or kind) and
  // nlohmann::json::exception (stored JSON that is not a record's).
  void (*set)(TestRecord&, const ColumnValue&);
};

// The name of the column holding the record's JSON (everything but the curves): a reader
// applies it first, the other columns then override it (they are authoritative, db/schema.h).
inline constexpr const char kRecordColumn[] = "record";

// Every column, in the export's order (the entries not exported anywhere among them).
std::span<const TestColumn> TestColumns();

// The column called `name`; std::out_of_range naming it when there is none.
const TestColumn& TestColumnNamed(const std::string& name);

// Cell conversions for setters and writers: NULL reads as "" and 0; std::invalid_argument
// for a cell of another kind.
std::string ColumnText(const ColumnValue& v);
std::int64_t ColumnInt(const ColumnValue& v);

}  // namespace eol::db
