// The statistics report behind `eol stats` and GET /api/stats: the store's measurement rows
// grouped per recipe (hash) and measurement, fed to analysis/qc/statistics.h and spc.h.
//
//   capability over the production tests' PASS and FAIL units by default (population "all";
//     "pass" for the PASS units only; ERROR tests said nothing about the motor and never
//     count), against the limits the units were judged with (stored with each measurement):
//     n, FAIL units, mean, sd, min, max; Cp/Cpk from the within-subgroup sigma (MRbar/1.128
//     for subgroup 1, Rbar/d2 for subgroups of 2..10 consecutive units), Pp/Ppk from the
//     overall sd, with a caveat below 30 units;
//   the control chart (I chart, or X-bar with subgroups): limits from the first `baseline`
//     PASS units, every unit's point against them, its run-rule alarms (rules 1-3 of
//     analysis/qc/spc.h), each naming the unit and serial (station/reports/spc_charts.h);
//   drift (the trend test) over the passing production tests in test order (a rejected
//     defect is not a trend), with the alarm and its message;
//   a type-1 gauge study when a serial is given: its PASS/FAIL tests (production or
//     self-check) under the recipe of its newest test.
// Self-check (master) tests never enter the production figures.
//
// {"window": {"from", "to", "recipe_hash", "population", "subgroup", "baseline"},
//  "recipes": [{"recipe_id", "recipe_version", "recipe_hash", "tests", "outcomes": {...},
//               "measurements": [{"name", "unit", "lo", "hi", "population", "n", "fail",
//                                 "mean", "sd", "min", "max", "cp", "cpk", "pp", "ppk",
//                                 "sigma_within", "sigma_within_method", "message", "caveat",
//                                 "control": {"chart", "baseline_units", "baseline", "caveat",
//                                             "centre", "lcl", "ucl", "alarms": [
//                                   {"rule", "index", "first", "value", "serial", "message"}]},
//                                 "drift": {...}}]}],
//  "alarms": ["<recipe id> v<version>: drift alarm: ..."],
//  "spc_alarms": ["<recipe id> v<version>: resonance_f_hz rule 2: ... (serial ...)"],
//  "gauge": null | {"serial", "recipe_hash", "tests", "tolerance_share", "sigma_span",
//                   "measurements": [{"name", "unit", "lo", "hi", "n", "mean", "sd",
//                                     "tolerance", "cg", "cgk", "reference", "bias",
//                                     "repeatable", "capable", "usable", "message"}]}}
// Numbers that do not exist (Cp with a one-sided limit, Cgk without a reference) are null.
#pragma once

#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "analysis/qc/statistics.h"
#include "db/store.h"
#include "station/reports/spc_charts.h"

namespace eol::station {

struct StatsRequest {
  std::optional<std::string> from;  // ISO 8601 on started_at, inclusive
  std::optional<std::string> to;    // exclusive
  std::optional<std::string> recipe_hash;
  std::optional<std::string> gauge_serial;
  std::map<std::string, double> reference;        // gauge reference value per measurement name
  Population population = Population::kMeasured;  // the units of capability and charts
  std::size_t baseline = kDefaultBaselineUnits;   // control limits from this many PASS units
  std::size_t subgroup = 1;  // 1: I-MR (sigma within MRbar/1.128); 2..10: X-bar/R (Rbar/d2)
  analysis::SpcRuleOptions rules;
  analysis::DriftOptions drift;
  analysis::GaugeOptions gauge;
};

// Empty when valid; otherwise the reason naming the field.
std::string ValidateStatsRequest(const StatsRequest& request);

// Reads the store (throws db::StoreError).
nlohmann::json StatsReport(db::Store& store, const StatsRequest& request);

// "resonance_f_hz=390.2" -> {name, value}; false with the reason otherwise.
bool ParseReference(const std::string& text, std::map<std::string, double>& into, std::string* why);

}  // namespace eol::station
