#include "station/stats_report.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "station/serial_number.h"

namespace eol::station {
namespace {

nlohmann::json Opt(const std::optional<double>& v) {
  return v && std::isfinite(*v) ? nlohmann::json(*v) : nlohmann::json();
}

// One measurement of one recipe: values in test order with the outcome of their test.
struct Series {
  std::string unit;
  analysis::Limit limit;
  std::vector<double> measured;  // PASS and FAIL tests
  std::vector<double> passing;   // PASS tests
  std::vector<std::string> measured_serials, passing_serials;
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
    Series& s = g.series[r.name];
    s.unit = r.unit;
    s.limit.lo = r.lo;
    s.limit.hi = r.hi;
    if (r.value) s.measured.push_back(*r.value);
  }
  out["tests"] = g.tests.size();
  for (const std::string& name : g.order) {
    const Series& s = g.series[name];
    std::optional<double> ref;
    if (const auto it = req.reference.find(name); it != req.reference.end()) ref = it->second;
    const analysis::GaugeStudy st = analysis::GaugeType1(s.measured, s.limit, ref, req.gauge);
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

}  // namespace

std::string ValidateStatsRequest(const StatsRequest& r) {
  std::string why;
  if (!r.drift.IsValid(&why)) return "drift: " + why;
  if (!r.gauge.IsValid(&why)) return "gauge: " + why;
  if (r.subgroup != 1 && !analysis::SpcConstantsFor(r.subgroup))
    return "subgroup must be 1 (I-MR) or 2..10 (X-bar/R)";
  if (!r.rules.IsValid(&why)) return "rules: " + why;
  if (r.gauge_serial && !ValidSerial(*r.gauge_serial, &why)) return "gauge: " + why;
  if (r.from && r.to && !(*r.from < *r.to)) return "from must be before to";
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
    Series& s = g.series[r.name];
    s.unit = r.unit;
    s.limit.lo = r.lo;  // one recipe hash: one set of limits
    s.limit.hi = r.hi;
    if (!r.value || r.outcome == analysis::Outcome::kError) continue;
    s.measured.push_back(*r.value);
    s.measured_serials.push_back(r.serial);
    if (r.outcome == analysis::Outcome::kPass) {
      s.passing.push_back(*r.value);
      s.passing_serials.push_back(r.serial);
    }
  }

  nlohmann::json recipes = nlohmann::json::array();
  nlohmann::json alarms = nlohmann::json::array();
  nlohmann::json spc_alarms = nlohmann::json::array();
  for (const std::string& hash : hashes) {
    Group& g = groups[hash];
    nlohmann::json measurements = nlohmann::json::array();
    for (const std::string& name : g.order) {
      const Series& s = g.series[name];
      const bool pass_only = req.population == Population::kPass;
      SpcSeries pop;
      pop.measurement = name;
      pop.unit = s.unit;
      pop.limit = s.limit;
      pop.population = req.population;
      pop.values = pass_only ? s.passing : s.measured;
      pop.serials = pass_only ? s.passing_serials : s.measured_serials;
      const analysis::CapabilityIndices c =
          analysis::ComputeCapabilityIndices(pop.values, s.limit, req.subgroup);
      const analysis::DriftSummary d =
          analysis::DetectDrift(s.passing, s.limit, name, s.unit, req.drift);
      const std::string who = g.recipe_id + " v" + std::to_string(g.recipe_version) + ": ";
      if (d.alarm) alarms.push_back(who + d.message);
      nlohmann::json control = {{"chart", req.subgroup > 1 ? "xbar_r" : "imr"},
                                {"centre", nullptr},
                                {"lcl", nullptr},
                                {"ucl", nullptr},
                                {"alarms", nlohmann::json::array()}};
      std::optional<analysis::ControlLimits> limits;
      std::vector<double> points;
      if (req.subgroup > 1) {
        const analysis::XbarRChart xr = analysis::ComputeXbarR(pop.values, req.subgroup);
        if (xr.usable) {
          limits = xr.xbar;
          points = xr.means;
        }
      } else {
        const analysis::IMrChart imr = analysis::ComputeIMr(pop.values);
        if (imr.usable) {
          limits = imr.individuals;
          points = pop.values;
        }
      }
      if (limits) {
        const std::vector<NamedAlarm> named =
            NameAlarms(analysis::ApplyRunRules(points, *limits, req.rules), pop, req.subgroup);
        for (const NamedAlarm& a : named) spc_alarms.push_back(who + a.text);
        control["centre"] = limits->centre;
        control["lcl"] = limits->lcl;
        control["ucl"] = limits->ucl;
        control["alarms"] = AlarmsJson(named);
      }
      const bool have = c.sample.n > 0;
      measurements.push_back(
          {{"name", name},
           {"unit", s.unit},
           {"lo", Opt(s.limit.lo)},
           {"hi", Opt(s.limit.hi)},
           {"population", PopulationText(req.population)},
           {"n", c.sample.n},
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
           {"control", control},
           {"drift", DriftJson(d)}});
    }
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
      {"subgroup", req.subgroup}};
  return {{"window", window},
          {"recipes", recipes},
          {"alarms", alarms},
          {"spc_alarms", spc_alarms},
          {"gauge", req.gauge_serial ? GaugeReport(store, req) : nlohmann::json()}};
}

}  // namespace eol::station
