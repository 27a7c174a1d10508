#include "station/daemon/central/central_record.h"

#include <nlohmann/json.hpp>

#include "db/test_columns.h"
#include "station/daemon/central/central_schema.h"

namespace eol::station::central {
namespace {

// jsonb cannot hold U+0000; a garbled device reply must not block the replication queue.
void ReplaceNul(nlohmann::json& j) {
  if (j.is_string()) {
    std::string& s = j.get_ref<std::string&>();
    for (std::size_t at = s.find('\0'); at != std::string::npos; at = s.find('\0', at))
      s.replace(at, 1, "\xEF\xBF\xBD");
  } else if (j.is_structured()) {
    for (auto& v : j) ReplaceNul(v);
  }
}

std::string Text(nlohmann::json j) {
  ReplaceNul(j);
  return j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

// A text column: valid UTF-8 (invalid bytes become U+FFFD), no NUL.
std::string Clean(const std::string& s) {
  return nlohmann::json::parse(Text(nlohmann::json(s))).get<std::string>();
}

}  // namespace

void EnsureCentralSchema(PgConnection& pg) {
  pg.Run("BEGIN", "create the central schema (begin)");
  try {
    pg.Exec("SELECT pg_advisory_xact_lock($1::bigint)", {std::to_string(kSchemaLockKey)},
            "create the central schema (lock)");
    pg.Run(kCreateCentralSchema, "create the central schema");
    pg.Run("COMMIT", "create the central schema (commit)");
  } catch (...) {
    if (pg.ok()) pg.Run("ROLLBACK", "create the central schema (roll back)");
    throw;
  }
}

namespace {

// A cell of a central column of type `type` (db/test_columns.h): text valid UTF-8 without NUL,
// an empty time NULL, JSON as its text.
std::optional<std::string> CentralParam(const db::ColumnValue& v, std::string_view type) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return std::to_string(*i);
  if (const auto* j = std::get_if<nlohmann::json>(&v)) return Text(*j);
  if (const auto* t = std::get_if<std::string>(&v)) {
    if (type == "timestamptz") {
      if (t->empty()) return std::nullopt;
      return *t;
    }
    return Clean(*t);
  }
  return std::nullopt;
}

// "INSERT INTO tests (<test columns>, curves, stored_at) VALUES ($1::<type>, ...) ON CONFLICT
// (station_id, test_id) DO NOTHING": the central columns of db/test_columns.h in list order.
const std::string& InsertSql() {
  static const std::string sql = [] {
    std::string names, values;
    int i = 0;
    const auto add = [&](const std::string& name, const std::string& type) {
      const std::string sep = i == 0 ? "" : ", ";
      ++i;
      names += sep + name;
      values += sep + "$" + std::to_string(i) + (type == "text" ? "" : "::" + type);
    };
    for (const db::TestColumn& c : db::TestColumns())
      if (c.central_name != nullptr) add(c.central_name, c.central_type);
    add("curves", "jsonb");
    add("stored_at", "timestamptz");
    return "INSERT INTO tests (" + names + ") VALUES (" + values +
           ") ON CONFLICT (station_id, test_id) DO NOTHING";
  }();
  return sql;
}

}  // namespace

bool InsertCentral(PgConnection& pg, const db::TestRecord& r, const std::string& stored_at) {
  PgParams params;
  for (const db::TestColumn& c : db::TestColumns())
    if (c.central_name != nullptr) params.push_back(CentralParam(c.get(r), c.central_type));
  params.push_back(Text(nlohmann::json(r.curves)));
  params.push_back(stored_at);
  return pg.Exec(InsertSql(), params,
                 "insert test " + std::to_string(r.id) + " of station '" + r.station_id + "'")
             .affected() == 1;
}

std::vector<db::TestRecord> CentralTestsOfSerial(PgConnection& pg, const std::string& serial,
                                                 bool with_curves, int limit) {
  const std::string sql = std::string("SELECT record") + (with_curves ? ", curves" : "") +
                          " FROM tests WHERE serial = $1 "
                          "ORDER BY started_at DESC, station_id, test_id DESC LIMIT $2::integer";
  const PgResult res =
      pg.Exec(sql, {serial, std::to_string(limit)}, "read the tests of serial '" + serial + "'");
  std::vector<db::TestRecord> out;
  out.reserve(static_cast<std::size_t>(res.rows()));
  for (int i = 0; i < res.rows(); ++i) {
    try {
      db::TestRecord r = nlohmann::json::parse(res.Text(i, 0)).get<db::TestRecord>();
      if (with_curves)
        r.curves = nlohmann::json::parse(res.Text(i, 1)).get<std::vector<db::Curve>>();
      out.push_back(std::move(r));
    } catch (const std::exception& e) {
      throw PgError("postgres " + pg.where() + ": read the tests of serial '" + serial + "': row " +
                    std::to_string(i) + " is not a record: " + e.what());
    }
  }
  return out;
}

}  // namespace eol::station::central
