#include "station/daemon/central/central_record.h"

#include <nlohmann/json.hpp>

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

bool InsertCentral(PgConnection& pg, const db::TestRecord& r, const std::string& stored_at) {
  nlohmann::json record = r;
  const nlohmann::json curves = record["curves"];
  record.erase("curves");
  static const std::string kInsert = R"sql(
    INSERT INTO tests (station_id, test_id, serial, outcome, started_at, finished_at, kind,
                       recipe_id, recipe_version, recipe_sha256, software_version,
                       operator_id, shift, order_number, retest_of, reason_code, reasons,
                       record, curves, stored_at)
    VALUES ($1, $2::bigint, $3, $4, $5::timestamptz, $6::timestamptz, $7, $8, $9::integer, $10,
            $11, $12, $13, $14, $15::bigint, $16, $17::jsonb, $18::jsonb, $19::jsonb,
            $20::timestamptz)
    ON CONFLICT (station_id, test_id) DO NOTHING)sql";
  const auto opt = [](const std::string& s) -> std::optional<std::string> {
    if (s.empty()) return std::nullopt;
    return s;
  };
  const PgParams params = {
      Clean(r.station_id),
      std::to_string(r.id),
      Clean(r.serial),
      std::string(analysis::ToString(r.outcome)),
      r.started_at,
      opt(r.finished_at),
      std::string(db::ToString(r.kind)),
      Clean(r.recipe_id),
      std::to_string(r.recipe_version),
      r.recipe_hash,
      Clean(r.software_version),
      Clean(r.work.operator_id),
      Clean(r.work.shift),
      Clean(r.work.order_number),
      r.retest_of ? std::optional<std::string>(std::to_string(*r.retest_of)) : std::nullopt,
      r.reasons.empty() ? std::nullopt
                        : std::optional<std::string>(analysis::ToString(r.reasons.front().code)),
      Text(nlohmann::json(r.reasons)),
      Text(record),
      Text(curves),
      stored_at};
  return pg.Exec(kInsert, params,
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
