#include "station/reports/stats_report.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "db/serial_number.h"

namespace eol::station {
namespace {

nlohmann::json Opt(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json();
}

// One measurement of one recipe: values in test order with the outcome of their test.
// One measurement's units under one recipe, in test order: the SPC series of every measured
// unit (PASS and FAIL, `failed` marking the FAILs) and the PASS values for the drift test.
struct Series {
  SpcSeries measured;
  std::vector<double> passing;
};

struct Group {
  std::string recipe_id;
  int recipe_version = 0;
  std::vector<std::int64_t> tests;  // ids in order, distinct
  std::map<std::string, int> outcomes;
  std::vector<std::string> order;  // measurement names in first-seen order
  std::map<std::string, Series> series;
};

nlohmann::json DriftJson(const analysis::DriftSummary& d) {
  return {{"usable", d.usable},
          {"alarm", d.alarm},
          {"n", d.n},
          {"slope_per_test", d.usable ? nlohmann::json(d.slope_per_test) : nlohmann::json()},
          {"slope_sigma", d.usable ? nlohmann::json(d.slope_sigma) : nlohmann::json()},
          {"t", d.usable && std::isfinite(d.t) ? nlohmann::json(d.t) : nlohmann::json()},
          {"change", d.usable ? nlohmann::json(d.change) : nlohmann::json()},
          {"change_of_tolerance", Opt(d.change_of_tolerance)},
          {"message", d.message}};
}

nlohmann::json GaugeReport(db::Store& store, const StatsRequest& req) {
  std::vector<db::MeasurementRow> rows;
  for (const db::RecordKind kind : db::kAllRecordKinds) {
    db::MeasurementQuery q;
    q.from = req.from;
    q.to = req.to;
    q.recipe_hash = req.recipe_hash;
    q.serial = req.gauge_serial;
    q.kind = kind;
    for (auto& r : store.MeasurementRows(q)) rows.push_back(std::move(r));
  }
  std::stable_sort(rows.begin(), rows.end(), [](const auto& a, const auto& b) {
    return a.started_at != b.started_at ? a.started_at < b.started_at : a.test_id < b.test_id;
  });
  nlohmann::json out = {{"serial", *req.gauge_serial},
                        {"tolerance_share", req.gauge.tolerance_share},
                        {"sigma_span", req.gauge.sigma_span},
                        {"recipe_hash", nullptr},
                        {"tests", 0},
                        {"measurements", nlohmann::json::array()}};
  std::string hash;
  for (const auto& r : rows)
    if (r.outcome != analysis::Outcome::kError) hash = r.recipe_hash;  // the newest measured
  if (hash.empty()) return out;
  out["recipe_hash"] = hash;
  Group g;
  for (const auto& r : rows) {
    if (r.recipe_hash != hash || r.outcome == analysis::Outcome::kError) continue;
    if (g.tests.empty() || g.tests.back() != r.test_id) g.tests.push_back(r.test_id);
    if (!g.series.count(r.name)) g.order.push_back(r.name);
    SpcSeries& s = g.series[r.name].measured;
    s.unit = r.unit;
    s.limit.lo = r.lo;
    s.limit.hi = r.hi;
    if (r.value) s.values.push_back(*r.value);
  }
  out["tests"] = g.tests.size();
  for (const std::string& name : g.order) {
    const SpcSeries& s = g.series[name].measured;
    std::optional<double> ref;
    if (const auto it = req.reference.find(name); it != req.reference.end()) ref = it->second;
    const analysis::GaugeStudy st = analysis::GaugeType1(s.values, s.limit, ref, req.gauge);
    out["measurements"].push_back(
        {{"name", name},
         {"unit", s.unit},
         {"lo", Opt(s.limit.lo)},
         {"hi", Opt(s.limit.hi)},
         {"n", st.sample.n},
         {"mean", st.sample.n ? nlohmann::json(st.sample.mean) : nlohmann::json()},
         {"sd", st.sample.n > 1 ? nlohmann::json(st.sample.sd) : nlohmann::json()},
         {"tolerance", st.tolerance > 0 ? nlohmann::json(st.tolerance) : nlohmann::json()},
         {"cg", st.usable ? nlohmann::json(st.cg) : nlohmann::json()},
         {"cgk", Opt(st.cgk)},
         {"reference", Opt(st.reference)},
         {"bias", Opt(st.bias)},
         {"repeatable", st.repeatable},
         {"capable", st.capable ? nlohmann::json(*st.capable) : nlohmann::json()},
         {"usable", st.usable},
         {"message", st.message}});
  }
  return out;
}

// The control chart of one measurement: limits from its baseline PASS units, the points of every
// unit against them, and the run-rule alarms (also appended to `spc_alarms`).
nlohmann::json ControlJson(const SpcSeries& m, const StatsRequest& req, const std::string& who,
                           nlohmann::json& spc_alarms) {
  const Baseline b = BaselineOf(m, req.baseline);
  const analysis::PhasedChart c = analysis::ComputePhasedChart(m.values, b.values, req.subgroup);
  nlohmann::json control = {{"chart", req.subgroup > 1 ? "xbar_r" : "imr"},
                            {"baseline_units", b.values.size()},
                            {"baseline", b.text},
                            {"caveat", c.caveat},
                            {"centre", nullptr},
                            {"lcl", nullptr},
                            {"ucl", nullptr},
                            {"alarms", nlohmann::json::array()}};
  if (!c.usable) return control;
  const std::vector<NamedAlarm> named =
      NameAlarms(analysis::ApplyRunRules(c.points, c.centre, req.rules), m, req.subgroup);
  for (const NamedAlarm& a : named) spc_alarms.push_back(who + a.text);
  control["centre"] = c.centre.centre;
  control["lcl"] = c.centre.lcl;
  control["ucl"] = c.centre.ucl;
  control["alarms"] = AlarmsJson(named);
  return control;
}

// One measurement's figures: capability of the charted units, control chart, drift of the
// PASS units (a rejected defect is not a trend).
nlohmann::json MeasurementJson(const Series& s, const StatsRequest& req, const std::string& who,
                               nlohmann::json& alarms, nlohmann::json& spc_alarms) {
  const SpcSeries& m = s.measured;
  const analysis::CapabilityIndices c =
      analysis::ComputeCapabilityIndices(m.values, m.limit, req.subgroup);
  const analysis::DriftSummary d =
      analysis::DetectDrift(s.passing, m.limit, m.measurement, m.unit, req.drift);
  if (d.alarm) alarms.push_back(who + d.message);
  const bool have = c.sample.n > 0;
  return {{"name", m.measurement},
          {"unit", m.unit},
          {"lo", Opt(m.limit.lo)},
          {"hi", Opt(m.limit.hi)},
          {"population", PopulationText(req.population)},
          {"n", c.sample.n},
          {"fail", std::count(m.failed.begin(), m.failed.end(), true)},
          {"mean", have ? nlohmann::json(c.sample.mean) : nlohmann::json()},
          {"sd", c.sample.n > 1 ? nlohmann::json(c.sample.sd) : nlohmann::json()},
          {"min", have ? nlohmann::json(c.sample.min) : nlohmann::json()},
          {"max", have ? nlohmann::json(c.sample.max) : nlohmann::json()},
          {"cp", Opt(c.cp)},
          {"cpk", Opt(c.cpk)},
          {"pp", Opt(c.pp)},
          {"ppk", Opt(c.ppk)},
          {"sigma_within", c.sigma_within > 0 ? nlohmann::json(c.sigma_within) : nlohmann::json()},
          {"sigma_within_method", c.within_method},
          {"message", c.message},
          {"caveat", c.caveat},
          {"control", ControlJson(m, req, who, spc_alarms)},
          {"drift", DriftJson(d)}};
}

}  // namespace

std::string ValidateStatsRequest(const StatsRequest& r) {
  std::string why;
  if (!r.drift.IsValid(&why)) return "drift: " + why;
  if (!r.gauge.IsValid(&why)) return "gauge: " + why;
  if (r.subgroup != 1 && !analysis::SpcConstantsFor(r.subgroup))
    return "subgroup must be 1 (I-MR) or 2..10 (X-bar/R)";
  if (!r.rules.IsValid(&why)) return "rules: " + why;
  if (r.gauge_serial && !db::ValidSerial(*r.gauge_serial, &why)) return "gauge: " + why;
  if (r.from && r.to && !(*r.from < *r.to)) return "from must be before to";
  if (r.baseline < 2) return "baseline must be at least 2 PASS units";
  return "";
}

bool ParseReference(const std::string& text, std::map<std::string, double>& into,
                    std::string* why) {
  const std::size_t eq = text.find_first_of("=:");
  if (eq == std::string::npos || eq == 0) {
    *why = "reference '" + text + "' must be NAME=VALUE (e.g. resonance_f_hz=390.2)";
    return false;
  }
  const std::string value = text.substr(eq + 1);
  try {
    std::size_t used = 0;
    const double v = std::stod(value, &used);
    if (used != value.size() || !std::isfinite(v)) throw std::invalid_argument(value);
    into[text.substr(0, eq)] = v;
  } catch (const std::exception&) {
    *why = "reference '" + text + "': '" + value + "' is not a number";
    return false;
  }
  return true;
}

nlohmann::json StatsReport(db::Store& store, const StatsRequest& req) {
  db::MeasurementQuery q;
  q.from = req.from;
  q.to = req.to;
  q.recipe_hash = req.recipe_hash;
  q.kind = db::RecordKind::kProduction;
  const std::vector<db::MeasurementRow> rows = store.MeasurementRows(q);

  std::vector<std::string> hashes;  // first-seen order
  std::map<std::string, Group> groups;
  for (const auto& r : rows) {
    auto [it, fresh] = groups.try_emplace(r.recipe_hash);
    Group& g = it->second;
    if (fresh) hashes.push_back(r.recipe_hash);
    g.recipe_id = r.recipe_id;
    g.recipe_version = r.recipe_version;
    if (g.tests.empty() || g.tests.back() != r.test_id) {
      g.tests.push_back(r.test_id);
      ++g.outcomes[analysis::ToString(r.outcome)];
    }
    if (!g.series.count(r.name)) g.order.push_back(r.name);
    SpcSeries& m = g.series[r.name].measured;
    m.measurement = r.name;
    m.unit = r.unit;
    m.limit.lo = r.lo;  // one recipe hash: one set of limits
    m.limit.hi = r.hi;
    m.population = req.population;
    const bool pass = r.outcome == analysis::Outcome::kPass;
    if (!r.value || (r.outcome != analysis::Outcome::kFail && !pass)) continue;
    if (pass) g.series[r.name].passing.push_back(*r.value);
    if (!pass && req.population == Population::kPass) continue;
    m.values.push_back(*r.value);
    m.serials.push_back(r.serial);
    m.failed.push_back(!pass);
  }

  nlohmann::json recipes = nlohmann::json::array();
  nlohmann::json alarms = nlohmann::json::array();
  nlohmann::json spc_alarms = nlohmann::json::array();
  for (const std::string& hash : hashes) {
    Group& g = groups[hash];
    const std::string who = g.recipe_id + " v" + std::to_string(g.recipe_version) + ": ";
    nlohmann::json measurements = nlohmann::json::array();
    for (const std::string& name : g.order)
      measurements.push_back(MeasurementJson(g.series[name], req, who, alarms, spc_alarms));
    recipes.push_back({{"recipe_id", g.recipe_id},
                       {"recipe_version", g.recipe_version},
                       {"recipe_hash", hash},
                       {"tests", g.tests.size()},
                       {"outcomes", g.outcomes},
                       {"measurements", measurements}});
  }
  nlohmann::json window = {
      {"from", req.from ? nlohmann::json(*req.from) : nlohmann::json()},
      {"to", req.to ? nlohmann::json(*req.to) : nlohmann::json()},
      {"recipe_hash", req.recipe_hash ? nlohmann::json(*req.recipe_hash) : nlohmann::json()},
      {"population", PopulationText(req.population)},
      {"subgroup", req.subgroup},
      {"baseline", req.baseline}};
  return {{"window", window},
          {"recipes", recipes},
          {"alarms", alarms},
          {"spc_alarms", spc_alarms},
          {"gauge", req.gauge_serial ? GaugeReport(store, req) : nlohmann::json()}};
}

}  // namespace eol::station
