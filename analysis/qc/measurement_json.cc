#include "analysis/qc/measurement_json.h"

#include <string>

#include "analysis/enum_names.h"
#include "analysis/json_number.h"

namespace eol::analysis {

void to_json(nlohmann::json& j, const Outcome& o) { j = ToString(o); }

void from_json(const nlohmann::json& j, Outcome& o) {
  o = ParseEnumOrThrow("outcome", j.get<std::string>(), kAllOutcomes);
}

void to_json(nlohmann::json& j, const MeasurementOutcome& o) { j = ToString(o); }

void from_json(const nlohmann::json& j, MeasurementOutcome& o) {
  o = ParseEnumOrThrow("measurement outcome", j.get<std::string>(), kAllMeasurementOutcomes);
}

void to_json(nlohmann::json& j, const Limit& l) {
  j = nlohmann::json::object();
  j["lo"] = l.lo ? nlohmann::json(*l.lo) : nlohmann::json();
  j["hi"] = l.hi ? nlohmann::json(*l.hi) : nlohmann::json();
  j["marginal"] = l.marginal;
}

void from_json(const nlohmann::json& j, Limit& l) {
  l = Limit{};
  if (j.contains("lo") && !j.at("lo").is_null()) l.lo = j.at("lo").get<double>();
  if (j.contains("hi") && !j.at("hi").is_null()) l.hi = j.at("hi").get<double>();
  l.marginal = j.value("marginal", 0.0);
}

void to_json(nlohmann::json& j, const Measurement& m) {
  j = {{"name", m.name},
       {"unit", m.unit},
       {"doc", m.doc},
       {"value", JsonNumber(m.value)},
       {"sigma", JsonNumber(m.sigma)},
       {"limit", m.limit},
       {"outcome", m.outcome},
       {"marginal", m.marginal}};
}

void from_json(const nlohmann::json& j, Measurement& m) {
  m.name = j.at("name").get<std::string>();
  m.unit = j.value("unit", "");
  m.doc = j.value("doc", "");
  m.value = NumberOrNaN(j, "value");
  m.sigma = NumberOrNaN(j, "sigma");
  m.limit = j.value("limit", Limit{});
  m.outcome = j.value("outcome", MeasurementOutcome::kUnset);
  m.marginal = j.value("marginal", false);
}

void to_json(nlohmann::json& j, const Reason& r) {
  j = {{"code", ToString(r.code)}, {"text", r.text}};
  if (!r.cause.empty()) j["cause"] = r.cause;
}

void from_json(const nlohmann::json& j, Reason& r) {
  if (j.is_string()) {  // stored before reasons had codes
    r = {ReasonCode::kLegacy, j.get<std::string>()};
    return;
  }
  const std::string code = j.at("code").get<std::string>();
  const auto parsed = ParseReasonCode(code);
  if (!parsed)
    throw nlohmann::json::other_error::create(501, "reasons: unknown code '" + code + "'", &j);
  r = {*parsed, j.at("text").get<std::string>(), j.value("cause", std::string())};
}

void to_json(nlohmann::json& j, const Verdict& v) {
  j = {{"outcome", v.outcome}, {"reasons", v.reasons}, {"measurements", v.measurements}};
}

void from_json(const nlohmann::json& j, Verdict& v) {
  v.outcome = j.at("outcome").get<Outcome>();
  v.reasons = j.value("reasons", std::vector<Reason>{});
  v.measurements = j.value("measurements", std::vector<Measurement>{});
}

}  // namespace eol::analysis
