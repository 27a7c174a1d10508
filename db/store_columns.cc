#include "db/store_columns.h"

#include <array>
#include <stdexcept>
#include <vector>

namespace eol::db::internal {
namespace {

// The columns StoreWrite `w` writes, in list order.
const std::vector<const TestColumn*>& Written(StoreWrite w) {
  static const std::array<std::vector<const TestColumn*>, 4> by_write = [] {
    std::array<std::vector<const TestColumn*>, 4> out;
    for (const TestColumn& c : TestColumns())
      out.at(static_cast<std::size_t>(c.store)).push_back(&c);
    return out;
  }();
  return by_write.at(static_cast<std::size_t>(w));
}

// Every column of the store's table, in list order.
const std::vector<const TestColumn*>& Stored() {
  static const std::vector<const TestColumn*> stored = [] {
    std::vector<const TestColumn*> out;
    for (const TestColumn& c : TestColumns())
      if (c.store != StoreWrite::kNone) out.push_back(&c);
    return out;
  }();
  return stored;
}

// Invalid UTF-8 in a string (a garbled barcode, a device's reply) must not lose the record.
std::string Dump(const nlohmann::json& j) {
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

void Bind(Statement& s, int i, const ColumnValue& v) {
  if (const auto* n = std::get_if<std::int64_t>(&v))
    s.BindInt(i, *n);
  else if (const auto* t = std::get_if<std::string>(&v))
    s.BindText(i, *t);
  else if (const auto* j = std::get_if<nlohmann::json>(&v))
    s.BindText(i, Dump(*j));
  else
    s.BindNull(i);
}

void BindAll(Statement& s, StoreWrite w, const TestRecord& record, int first) {
  int i = first;
  for (const TestColumn* c : Written(w)) Bind(s, i++, c->get(record));
}

ColumnValue Cell(const Statement& s, int i, const TestColumn& c) {
  if (s.IsNull(i)) return std::monostate{};
  if (std::string_view(c.sql_type) == "INTEGER") return s.Int(i);
  return s.Text(i);
}

int IndexOf(const char* name) {
  const auto& stored = Stored();
  for (std::size_t i = 0; i < stored.size(); ++i)
    if (std::string_view(stored[i]->name) == name) return static_cast<int>(i);
  throw std::logic_error(std::string("the store has no tests column ") + name);
}

// Sets `c` of `r` from column `i`, naming the test and the column when the value is not one.
void Apply(const Statement& s, int i, const TestColumn& c, const std::string& path,
           const std::string& op, TestRecord& r) {
  try {
    c.set(r, Cell(s, i, c));
  } catch (const nlohmann::json::exception& e) {
    throw StoreError(Message(
        path, op, std::string("stored JSON is not a record (column ") + c.name + "): " + e.what()));
  } catch (const std::invalid_argument& e) {  // an unknown enum string (test_record.h)
    throw StoreError(Message(path, op, std::string("column ") + c.name + ": " + e.what()));
  }
}

}  // namespace

const std::string& TestsInsertSql() {
  static const std::string sql = [] {
    std::string names = "id, retest_of, outcome", values;
    int i = 3;
    for (const TestColumn* c : Written(StoreWrite::kAtBegin)) {
      names += std::string(", ") + c->name;
      values += ", ?" + std::to_string(i++);
    }
    return "INSERT INTO tests (" + names +
           ") VALUES (max(?1, (SELECT coalesce(max(id), 0) + 1 FROM tests)), "
           "(SELECT min(id) FROM tests WHERE serial = ?2), 'RUNNING'" +
           values + ") RETURNING id, retest_of";
  }();
  return sql;
}

void BindBeginColumns(Statement& s, const TestRecord& record) {
  BindAll(s, StoreWrite::kAtBegin, record, 3);
}

const std::string& TestsFinishSql() {
  static const std::string sql = [] {
    std::string set;
    int i = 2;
    for (const TestColumn* c : Written(StoreWrite::kAtFinish))
      set += (set.empty() ? "" : ", ") + std::string(c->name) + " = ?" + std::to_string(i++);
    return "UPDATE tests SET " + set + " WHERE id = ?1 AND outcome = 'RUNNING'";
  }();
  return sql;
}

void BindFinishColumns(Statement& s, const TestRecord& record) {
  BindAll(s, StoreWrite::kAtFinish, record, 2);
}

const std::string& TestsSelectSql() {
  static const std::string sql = [] {
    std::string names;
    for (const TestColumn* c : Stored()) names += std::string(c->name) + ", ";
    return "SELECT " + names +
           "(SELECT count(*) FROM tests p WHERE p.serial = tests.serial AND p.id <= tests.id) "
           "FROM tests ";
  }();
  return sql;
}

TestRecord ReadTestRow(const Statement& s, const std::string& path) {
  static const int id_at = IndexOf("id");
  static const int record_at = IndexOf(kRecordColumn);
  const std::string op = "read test " + std::to_string(s.Int(id_at));
  const auto& stored = Stored();
  TestRecord r;
  Apply(s, record_at, *stored[record_at], path, op, r);
  for (std::size_t i = 0; i < stored.size(); ++i)
    if (static_cast<int>(i) != record_at) Apply(s, static_cast<int>(i), *stored[i], path, op, r);
  r.attempt = static_cast<int>(s.Int(static_cast<int>(stored.size())));
  r.curves.clear();
  return r;
}

TestColumnSet::TestColumnSet(std::initializer_list<const char*> names) {
  for (const char* name : names) columns_.push_back(Stored()[IndexOf(name)]);
}

std::string TestColumnSet::List(const std::string& prefix) const {
  std::string list;
  for (const TestColumn* c : columns_) list += (list.empty() ? "" : ", ") + prefix + c->name;
  return list;
}

void TestColumnSet::Read(const Statement& s, int first, const std::string& path,
                         const std::string& op, TestRecord& r) const {
  for (std::size_t i = 0; i < columns_.size(); ++i)
    Apply(s, first + static_cast<int>(i), *columns_[i], path, op, r);
}

}  // namespace eol::db::internal
