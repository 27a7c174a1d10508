// Yield of the production tests: first-pass and final yield, retest counts and a Pareto of
// the reasons, in total and per shift, day or recipe. Behind `eol stats --yield` and
// GET /api/yield (and the Pareto chart GET /api/yield/pareto.svg). ComputeYield is pure: the
// store's rows in, the figures out; YieldReport reads the store.
//
// Definitions (a unit is a serial; only production tests count, self-check masters never):
//   units         serials whose first stored test (db::OutcomeRow::retest_of empty: the
//                 first of any kind, in or before the window) started in the window. A unit
//                 belongs to the group (shift, day, recipe) of its first test.
//   its tests     its production tests in the window, in test order.
//   first pass    its first test is PASS. An ERROR or ABORTED first test is not a first pass,
//                 even when the next test PASSes: the unit went through the station twice (a
//                 cycle, a handling, an operator's time), and first-pass yield counts the
//                 units that went through once. It is not a FAIL either:
//   first verdict among the units with a PASS or FAIL test, those whose first PASS or FAIL
//                 test is PASS: the motors' yield with the station's ERRORs and ABORTs left
//                 out (an ERROR says nothing about the motor: analysis/qc/measurement.h).
//   final         its last test in the window: PASS (final pass), FAIL (final fail), or
//                 ERROR / ABORTED (open: not decided, counted neither PASS nor FAIL; final
//                 yield = final pass / units, so an open unit lowers it until it is decided).
//   retested      units with more than one test; tests per unit = their tests / units.
//   tests         every production test in the window in the group of its own start time or
//                 recipe, including "carried over" tests of serials first tested before the
//                 window (they count in the tests and the Pareto, not as units).
//   Pareto        each non-PASS test of the group counts once, under its decisive (first)
//                 reason's code ("none" when it has no reason); units: the distinct serials;
//                 sorted by tests (then code), with each code's share of the non-PASS tests
//                 and the cumulative share.
// Times: a test's day is the local calendar date of its start; its shift the one of
// `shifts` (local start times, each running until the next; the last one past midnight until
// the first) whose start it follows, keyed by the date on which that shift began
// ("2026-11-20 C" for 02:00 on the 21st). Local time is the station's time zone (with its
// daylight saving rules) unless utc_offset_min fixes it.
//
// JSON: {"window": {"from", "to", "recipe_hash", "by", "shifts", "time_zone"},
//        "total": GROUP, "groups": [GROUP, ...] (empty for by "all")}
//   GROUP: {"key", "units", "first_pass", "first_pass_yield", "first_verdict_units",
//           "first_verdict_pass", "first_verdict_yield", "final_pass", "final_fail",
//           "final_open", "final_yield", "retested_units", "unit_tests", "tests_per_unit",
//           "tests", "carried_over_tests", "outcomes": {"PASS", "FAIL", "ERROR", "ABORTED"},
//           "pareto": [{"code", "tests", "units", "share", "cumulative"}]}
//   yields and shares are fractions 0..1, null where there is nothing to divide by.
#pragma once

#include <cstddef>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "db/store.h"
#include "drivers/io/chart.h"

namespace eol::station {

enum class YieldGrouping { kAll, kShift, kDay, kRecipe };
// "all" | "shift" | "day" | "recipe"; false for any other text.
bool ParseYieldGrouping(const std::string& text, YieldGrouping* out);
const char* ToString(YieldGrouping g);

struct ShiftStart {
  std::string name;
  int minute = 0;  // local time of day, minutes after midnight
  bool operator==(const ShiftStart&) const = default;
};
// Three eight-hour shifts: "A=06:00,B=14:00,C=22:00".
inline constexpr char kDefaultShifts[] = "A=06:00,B=14:00,C=22:00";
// "NAME=HH:MM,..." (1..24 shifts, names of 1..16 letters, digits, '-' or '_', distinct, times
// 00:00..23:59 distinct): the shifts sorted by start; false with the reason naming the part
// ("'A=6' must be NAME=HH:MM ...").
bool ParseShifts(const std::string& text, std::vector<ShiftStart>* out, std::string* why);
std::string ShiftsText(const std::vector<ShiftStart>& shifts);  // "A=06:00,B=14:00,C=22:00"

struct YieldOptions {
  YieldGrouping by = YieldGrouping::kAll;
  std::vector<ShiftStart> shifts;  // empty: kDefaultShifts
  // Local time = UTC + this; nullopt: the station's time zone.
  std::optional<int> utc_offset_min;
};

struct ParetoEntry {
  std::string code;  // analysis::ToString(ReasonCode), or "none"
  std::size_t tests = 0;
  std::size_t units = 0;
  double share = 0.0;       // of the group's non-PASS tests
  double cumulative = 0.0;  // this and every code above it
};

struct YieldGroup {
  std::string key;  // "all", "2026-11-20", "2026-11-20 B", "pmsm-10pole v1 (aaaaaaaaaaaa)"
  std::size_t units = 0, first_pass = 0;
  std::size_t first_verdict_units = 0, first_verdict_pass = 0;
  std::size_t final_pass = 0, final_fail = 0, final_open = 0;
  std::size_t retested_units = 0, unit_tests = 0;
  std::size_t tests = 0, carried_over_tests = 0;
  std::map<analysis::Outcome, std::size_t> outcomes;  // of the group's tests
  std::vector<ParetoEntry> pareto;
};

struct YieldFigures {
  YieldGroup total;
  std::vector<YieldGroup> groups;  // in time (or recipe key) order; empty for kAll
};

// `rows` in test order (started_at, id), production tests only (Store::OutcomeRows). Throws
// std::invalid_argument naming the test for a started_at that is not the store's format.
YieldFigures ComputeYield(const std::vector<db::OutcomeRow>& rows, const YieldOptions& options);

nlohmann::json ToJson(const YieldGroup& g);

struct YieldRequest {
  std::optional<std::string> from, to;  // ISO 8601 on started_at; from inclusive, to exclusive
  std::optional<std::string> recipe_hash;
  YieldOptions options;
};

// Reads the store (throws db::StoreError) and computes: the JSON above.
nlohmann::json YieldReport(db::Store& store, const YieldRequest& request);

// The text `eol stats --yield` prints for YieldReport's JSON.
std::string YieldText(const nlohmann::json& report);

// The Pareto of `group` (a GROUP of YieldReport's JSON): one bar per code, its share of the
// non-PASS tests in %, rank on x (the legend names each rank's code with its counts), and the
// cumulative share as a line. Throws std::invalid_argument when the group has no non-PASS test.
io::Chart ParetoChart(const nlohmann::json& group, const std::string& title);

}  // namespace eol::station
