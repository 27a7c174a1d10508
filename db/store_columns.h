// The store's SQL for its tests table, derived from the one column list (db/test_columns.h):
// what BeginTest inserts, what FinishTest updates and how a row is read back into a record.
// Internal to eol::db (db/store*.cc only).
#pragma once

#include <initializer_list>
#include <string>
#include <vector>

#include "db/sqlite_statement.h"
#include "db/test_columns.h"
#include "db/test_record.h"

namespace eol::db::internal {

// INSERT of a new test: the id (?1 is the floor: the id is at least ?1 and above every other),
// retest_of (the first test of serial ?2), outcome 'RUNNING' and the StoreWrite::kAtBegin
// columns, bound by BindBeginColumns from ?3 on. RETURNING id, retest_of.
const std::string& TestsInsertSql();
void BindBeginColumns(Statement& s, const TestRecord& record);

// UPDATE of test ?1, still RUNNING, to the StoreWrite::kAtFinish columns (BindFinishColumns,
// from ?2 on).
const std::string& TestsFinishSql();
void BindFinishColumns(Statement& s, const TestRecord& record);

// "SELECT <every stored column>, <attempt> FROM tests " (a WHERE clause follows); the attempt
// counts the serial's tests up to this one in id order (db/test_record.h).
const std::string& TestsSelectSql();

// The record of the current row of a TestsSelectSql() statement, without curves. The record
// column first, then every other column over it. StoreError naming the test and the column
// for a value that is not a record's.
TestRecord ReadTestRow(const Statement& s, const std::string& path);

// A projection of the tests table for a query that needs only some columns (yield,
// statistics): the named stored columns, in the given order.
class TestColumnSet {
 public:
  // std::logic_error naming a name that is not a column of the store's tests table.
  explicit TestColumnSet(std::initializer_list<const char*> names);
  // "a, b, c", each name after `prefix` ("t." for a join).
  std::string List(const std::string& prefix = "") const;
  int size() const { return static_cast<int>(columns_.size()); }
  // Sets the fields of `r` the columns hold from columns first, first + 1, ... of the current
  // row of `s`; StoreError naming `op` and the column for a value that is not a record's.
  void Read(const Statement& s, int first, const std::string& path, const std::string& op,
            TestRecord& r) const;

 private:
  std::vector<const TestColumn*> columns_;
};

}  // namespace eol::db::internal
