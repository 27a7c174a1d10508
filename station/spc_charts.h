// Control charts and histograms of one stored measurement (resonance_f_hz, resonance_q, ...)
// for the engineer: the store's production units in test order (analysis/qc/spc.h computes),
// drawn with drivers/io/chart.h. Behind GET /api/charts/<measurement>.svg and
// `eol stats --plot`.
//
// Which units: production tests (self-check masters never) under one recipe, the request's
// recipe_hash or else the recipe of the newest test in the window (a chart across recipes
// would mix limits); by default the PASS units, or PASS and FAIL ("all"; an ERROR test says
// nothing about the motor and never counts). `last` keeps the newest N of them.
//
// Charts:
//   imr       individuals (centre, UCL/LCL = mean +- 2.66 MRbar, the recipe's limits as a band)
//             over moving ranges (UCL = 3.267 MRbar), run-rule alarms marked and listed;
//   xbar_r    subgroup means (xbarbar +- A2 Rbar) over ranges (D3, D4 Rbar), subgroups of
//             `subgroup` consecutive units;
//             the run rules watch the I or X-bar points; the MR and R charts show their limits;
//   histogram the values with the recipe's limits as vertical lines, and Cp/Cpk (within
//             sigma MRbar/d2: the units come one at a time), Pp/Ppk (overall s) printed.
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

struct ChartRequest {
  std::string measurement;              // a name of analysis/qc/measurement_names.h
  std::optional<std::string> from, to;  // ISO 8601 on started_at; from inclusive, to exclusive
  std::optional<std::string> recipe_hash;
  std::size_t last = 0;      // the newest N units; 0: every unit in the window
  std::size_t subgroup = 5;  // X-bar/R subgroups (xbar_r only); 2..10
  ChartKind kind = ChartKind::kIMr;
  Population population = Population::kPass;
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
  Population population = Population::kPass;
  std::vector<double> values;
  std::vector<std::string> serials;
  std::vector<std::string> started_at;
  std::size_t left_out_fail = 0;  // FAIL units not in a PASS-only population
};
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
                                        const analysis::SpcRuleOptions& rules = {});
io::Chart MeasurementChart(const SpcSeries& series, const ChartRequest& request);

}  // namespace eol::station
