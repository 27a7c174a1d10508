#include "db/test_record.h"

#include <cmath>
#include <limits>

#include "analysis/enum_names.h"

namespace eol::db {

const char* ToString(RecordKind k) {
  switch (k) {
    case RecordKind::kProduction:
      return "production";
    case RecordKind::kSelfCheck:
      return "self_check";
  }
  return "production";
}

RecordKind ParseRecordKind(std::string_view name) {
  return analysis::ParseEnumOrThrow("kind", name, kAllRecordKinds);
}

void to_json(nlohmann::json& j, const RecordKind& k) { j = ToString(k); }

void from_json(const nlohmann::json& j, RecordKind& k) {
  k = ParseRecordKind(j.get<std::string>());
}

void to_json(nlohmann::json& j, const Curve& c) {
  j = {{"name", c.name}, {"unit", c.unit}, {"freq_hz", c.freq_hz},
       {"re", c.re},     {"im", c.im},     {"sigma", c.sigma}};
}

namespace {
// JSON has no NaN: a sample that was not finite is written as null and reads back as NaN.
std::vector<double> Samples(const nlohmann::json& j, const char* key) {
  const nlohmann::json& a = j.at(key);
  if (!a.is_array())
    throw nlohmann::json::type_error::create(302, std::string(key) + ": must be an array", &a);
  std::vector<double> out;
  out.reserve(a.size());
  for (const nlohmann::json& v : a)
    out.push_back(v.is_null() ? std::numeric_limits<double>::quiet_NaN() : v.get<double>());
  return out;
}
}  // namespace

void from_json(const nlohmann::json& j, Curve& c) {
  c.name = j.at("name").get<std::string>();
  c.unit = j.value("unit", "");
  c.freq_hz = Samples(j, "freq_hz");
  c.re = Samples(j, "re");
  c.im = Samples(j, "im");
  c.sigma = j.contains("sigma") ? Samples(j, "sigma") : std::vector<double>{};
}

void to_json(nlohmann::json& j, const StateEntry& s) {
  j = {{"state", s.state}, {"t_ms", s.t_ms}, {"detail", s.detail}};
}

void from_json(const nlohmann::json& j, StateEntry& s) {
  s.state = j.at("state").get<std::string>();
  s.t_ms = j.value("t_ms", 0.0);
  s.detail = j.value("detail", "");
}

void to_json(nlohmann::json& j, const TestRecord& r) {
  j = {{"id", r.id},
       {"serial", r.serial},
       {"station_id", r.station_id},
       {"recipe", {{"id", r.recipe_id}, {"version", r.recipe_version}, {"hash", r.recipe_hash}}},
       {"software_version", r.software_version},
       {"started_at", r.started_at},
       {"finished_at", r.finished_at},
       {"retest_of", r.retest_of ? nlohmann::json(*r.retest_of) : nlohmann::json()},
       {"attempt", r.attempt},
       {"max_tests", r.max_tests},
       {"outcome", r.outcome},
       {"reasons", r.reasons},
       {"measurements", r.measurements},
       {"conditions", r.conditions},
       {"calibration", r.calibration},
       {"fit", r.fit},
       {"curves", r.curves},
       {"trace", r.trace},
       {"cycle_s", r.cycle_s},
       {"kind", r.kind},
       {"self_check", r.self_check},
       {"operator_id", r.work.operator_id},
       {"shift", r.work.shift},
       {"order_number", r.work.order_number}};
}

void from_json(const nlohmann::json& j, TestRecord& r) {
  r.id = j.value("id", std::int64_t{0});
  r.serial = j.at("serial").get<std::string>();
  r.station_id = j.value("station_id", "");
  const nlohmann::json& recipe = j.at("recipe");
  r.recipe_id = recipe.at("id").get<std::string>();
  r.recipe_version = recipe.value("version", 0);
  r.recipe_hash = recipe.value("hash", "");
  r.software_version = j.value("software_version", "");
  r.started_at = j.value("started_at", "");
  r.finished_at = j.value("finished_at", "");
  r.retest_of.reset();
  if (j.contains("retest_of") && !j.at("retest_of").is_null())
    r.retest_of = j.at("retest_of").get<std::int64_t>();
  r.attempt = j.value("attempt", 0);
  r.max_tests = j.value("max_tests", 0);
  r.outcome = j.at("outcome").get<analysis::Outcome>();
  r.reasons = j.value("reasons", std::vector<analysis::Reason>{});
  r.measurements = j.value("measurements", std::vector<analysis::Measurement>{});
  r.conditions = j.value("conditions", TestConditions{});
  r.calibration = j.value("calibration", nlohmann::json::object());
  r.fit = j.value("fit", nlohmann::json::object());
  r.curves = j.value("curves", std::vector<Curve>{});
  r.trace = j.value("trace", std::vector<StateEntry>{});
  r.cycle_s = j.value("cycle_s", std::map<std::string, double>{});
  r.kind = j.value("kind", RecordKind::kProduction);
  r.self_check = j.value("self_check", nlohmann::json::object());
  r.work.operator_id = j.value("operator_id", "");
  r.work.shift = j.value("shift", "");
  r.work.order_number = j.value("order_number", "");
}

}  // namespace eol::db
