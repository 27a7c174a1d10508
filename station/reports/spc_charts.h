// Control charts and histograms of one stored measurement (resonance_f_hz, resonance_q, ...)
// for the engineer: the store's production units in test order (analysis/qc/spc.h computes),
// drawn with drivers/io/chart.h. Behind GET /api/charts/<measurement>.svg and
// `eol stats --plot`.
//
// Which units: production tests (self-check masters never) under one recipe, the request's
// recipe_hash or else the recipe of the newest test in the window (a chart across recipes
// would mix limits); by default every measured unit, PASS and FAIL ("all"), or the PASS units
// only ("pass"); an ERROR test says nothing about the motor and never counts. `last` keeps the
// newest N of them.
//
// Control limits come from a baseline, the first `baseline` PASS units of the charted units
// (analysis/qc/spc.h "Baseline and monitoring"); every unit is charted against them, the FAIL
// units marked, so a run of bad units raises alarms instead of widening its own limits. The
// baseline (units, serials) and any small-sample caveat are printed on the chart.
//
// Charts:
//   imr       individuals (centre, UCL/LCL = mean +- 2.66 MRbar of the baseline, the recipe's
//             limits as a band) over moving ranges (UCL = 3.267 MRbar), run-rule alarms marked
//             and listed;
//   xbar_r    subgroup means (xbarbar +- A2 Rbar) over ranges (D3, D4 Rbar), subgroups of
//             `subgroup` consecutive units; no recipe limits (they bound units, not means);
//             the run rules watch the I or X-bar points; the MR and R charts show their limits;
//   histogram the values (FAIL units in their own colour) with the recipe's limits as
//             vertical lines, and Cp/Cpk (within sigma MRbar/d2: the units come one at a time),
//             Pp/Ppk (overall s) printed, with a caveat below 30 units.
// Numbers are printed to 4 significant digits.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"
#include "analysis/qc/spc.h"
#include "db/store.h"
#include "drivers/io/chart.h"

namespace eol::station {

enum class ChartKind { kIMr, kXbarR, kHistogram };
enum class Population { kPass, kMeasured };  // PASS units; PASS and FAIL units

// "imr" | "xbar_r" | "histogram"; "pass" | "all". False for any other text.
bool ParseChartKind(const std::string& text, ChartKind* out);
bool ParsePopulation(const std::string& text, Population* out);
std::string PopulationText(Population p);  // "PASS units" | "PASS and FAIL units"

// Control limits from the first this-many PASS units (all of them when there are fewer).
inline constexpr std::size_t kDefaultBaselineUnits = 50;

struct ChartRequest {
  std::string measurement;              // a name of analysis/qc/measurement_names.h
  std::optional<std::string> from, to;  // ISO 8601 on started_at; from inclusive, to exclusive
  std::optional<std::string> recipe_hash;
  std::size_t last = 0;      // the newest N units; 0: every unit in the window
  std::size_t subgroup = 5;  // X-bar/R subgroups (xbar_r only); 2..10
  ChartKind kind = ChartKind::kIMr;
  Population population = Population::kMeasured;
  std::size_t baseline = kDefaultBaselineUnits;  // 2..100000 PASS units
  analysis::SpcRuleOptions rules;
};
// Empty when valid; otherwise the reason naming the field.
std::string ValidateChartRequest(const ChartRequest& request);

// One measurement's units under one recipe, in test order (oldest first).
struct SpcSeries {
  std::string measurement, unit;
  std::string recipe_id, recipe_hash;
  int recipe_version = 0;
  analysis::Limit limit;  // the limits the units were judged against
  Population population = Population::kMeasured;
  std::vector<double> values;
  std::vector<std::string> serials;
  std::vector<std::string> started_at;
  std::vector<bool> failed;       // per unit: its test was FAIL
  std::size_t left_out_fail = 0;  // FAIL units not in a PASS-only population
};
// The control limits' baseline: the first `baseline` PASS units of the series, and the words
// that state it on a chart ("control limits from the first 50 PASS units, P-0001..P-0050").
struct Baseline {
  std::vector<double> values;
  std::string text;
};
Baseline BaselineOf(const SpcSeries& series, std::size_t baseline);
// Reads the store (throws db::StoreError); nullopt when no unit in the window measured it.
std::optional<SpcSeries> ReadSpcSeries(db::Store& store, const ChartRequest& request);

// Run-rule alarms of a chart with the units of the run named (1-based, in the chart's order):
// "... at unit 12 (serial P-0012)", "... at units 21-29 (serials P-0021..P-0029)" for an I
// chart, "... at subgroups 2-10, units 6-50 (serials ...)" for X-bar. `subgroup` 1 is the I
// chart.
struct NamedAlarm {
  analysis::SpcAlarm alarm;
  std::string serial;  // the unit (or the subgroup's last unit) that completed the run
  std::string text;    // the rule's message and the unit
};
std::vector<NamedAlarm> NameAlarms(const std::vector<analysis::SpcAlarm>& alarms,
                                   const SpcSeries& series, std::size_t subgroup);
nlohmann::json AlarmsJson(const std::vector<NamedAlarm>& alarms);

// The chart's panels (title, axes, limits, alarms, notes); the chart the request asks for.
std::vector<io::ChartPanel> ChartPanels(const SpcSeries& series, ChartKind kind,
                                        std::size_t subgroup,
                                        const analysis::SpcRuleOptions& rules = {},
                                        std::size_t baseline = kDefaultBaselineUnits);
io::Chart MeasurementChart(const SpcSeries& series, const ChartRequest& request);

}  // namespace eol::station
