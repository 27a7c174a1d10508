// `eol stats --db FILE [--recipe-hash H] [--from T] [--to T] [--population all|pass] [--baseline N]
//  [--subgroup N] [--gauge SERIAL] [--reference NAME=VALUE ...] [--gauge-sigma-span 6|4]
//  [--drift-t T] [--plot FILE.svg|.png] [--json]`:
// capability (Cp/Cpk within, Pp/Ppk overall), control-chart run-rule alarms, drift alarms and
// the type-1 gauge study (station/reports/stats_report.h); --plot draws the control charts and
// histograms of the resonance and its Q (station/reports/spc_charts.h).
// `eol stats --db FILE --yield [--by all|shift|day|recipe] [--shifts A=06:00,...]
//  [--utc-offset-min M] [--recipe-hash H] [--from T] [--to T] [--plot FILE] [--json]`:
// first-pass and final yield, retests and the Pareto of reasons (station/reports/yield.h); --plot
// draws the Pareto of the whole window. Exit 0, 2 on usage or file errors.
// Exit 0 when no drift (trend) alarm fired, 1 when one did, 2 on usage or file errors; run-rule
// alarms are printed and listed under "spc_alarms" but leave the exit code alone.
#include <algorithm>
#include <cstdio>
#include <functional>
#include <iostream>
#include <map>
#include <set>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "drivers/io/chart.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/reports/spc_charts.h"
#include "station/reports/stats_report.h"
#include "station/reports/yield.h"

namespace eol::station::cli {
namespace {

struct StatsArgs {
  std::string db;
  std::string recipe_hash;
  std::string from;
  std::string to;
  std::string gauge;
  std::vector<std::string> references;
  double sigma_span = 6.0;
  double drift_t = 4.0;
  std::string population = "all";
  std::size_t subgroup = 1;
  std::size_t baseline = kDefaultBaselineUnits;
  std::string plot;
  bool json = false;
  bool yield = false;
  std::string by = "all";
  std::string shifts = kDefaultShifts;
  std::optional<int> utc_offset_min;
  // Options given on the command line, by name ("--gauge"): what --yield refuses.
  std::vector<std::string> given;
};

std::string Num(const nlohmann::json& v, const char* fmt = "%.4g") {
  if (!v.is_number()) return "-";
  return analysis::Printf(fmt, v.get<double>());
}

void PrintText(const nlohmann::json& r) {
  std::printf(
      "capability over %s; Cp/Cpk from the within-subgroup sigma (%s), Pp/Ppk from the "
      "overall sd\n",
      r["window"]["population"].get<std::string>().c_str(),
      r["window"]["subgroup"].get<std::size_t>() > 1 ? "Rbar/d2" : "MRbar/1.128");
  for (const auto& g : r["recipes"]) {
    std::printf("recipe %s v%d (%s): %zu production tests\n",
                g["recipe_id"].get<std::string>().c_str(), g["recipe_version"].get<int>(),
                g["recipe_hash"].get<std::string>().substr(0, 12).c_str(),
                g["tests"].get<std::size_t>());
    std::printf("  %-34s %6s %12s %10s %8s %8s %8s %8s  %s\n", "measurement", "n", "mean", "sd",
                "Cp", "Cpk", "Pp", "Ppk", "drift");
    for (const auto& m : g["measurements"])
      std::printf(
          "  %-34s %6zu %12s %10s %8s %8s %8s %8s  %s\n", m["name"].get<std::string>().c_str(),
          m["n"].get<std::size_t>(), Num(m["mean"], "%.6g").c_str(), Num(m["sd"]).c_str(),
          Num(m["cp"], "%.3f").c_str(), Num(m["cpk"], "%.3f").c_str(), Num(m["pp"], "%.3f").c_str(),
          Num(m["ppk"], "%.3f").c_str(), m["drift"]["alarm"].get<bool>() ? "ALARM" : "-");
  }
  if (r["recipes"].empty()) std::printf("no production tests in the window\n");
  for (const auto& a : r["alarms"]) std::printf("ALARM %s\n", a.get<std::string>().c_str());
  for (const auto& a : r["spc_alarms"])
    std::printf("RUN-RULE ALARM %s\n", a.get<std::string>().c_str());
  if (r["gauge"].is_object()) {
    const auto& g = r["gauge"];
    std::printf("type-1 gauge study of %s: %zu tests (K = %.0f %% of the tolerance, %g sigma)\n",
                g["serial"].get<std::string>().c_str(), g["tests"].get<std::size_t>(),
                100.0 * g["tolerance_share"].get<double>(), g["sigma_span"].get<double>());
    for (const auto& m : g["measurements"])
      std::printf("  %-28s n %3zu  mean %-10s sd %-10s Cg %-7s Cgk %-7s %s\n",
                  m["name"].get<std::string>().c_str(), m["n"].get<std::size_t>(),
                  Num(m["mean"], "%.6g").c_str(), Num(m["sd"]).c_str(),
                  Num(m["cg"], "%.3f").c_str(), Num(m["cgk"], "%.3f").c_str(),
                  m["message"].get<std::string>().c_str());
  }
}

// The control charts (I-MR, or X-bar/R with --subgroup) and histograms of the resonance and
// its Q, one under the other, for the recipe of the newest test (or --recipe-hash).
void WritePlot(db::Store& store, const StatsRequest& req, const std::string& path) {
  io::Chart chart;
  for (const std::string_view name :
       {analysis::names::kResonanceFHz, analysis::names::kResonanceQ}) {
    ChartRequest c;
    c.measurement = std::string(name);
    c.from = req.from;
    c.to = req.to;
    c.recipe_hash = req.recipe_hash;
    c.population = req.population;
    c.baseline = req.baseline;
    const std::optional<SpcSeries> s = ReadSpcSeries(store, c);
    if (!s) continue;
    if (chart.title.empty())
      chart.title = "eol stats: recipe " + s->recipe_id + " v" + std::to_string(s->recipe_version) +
                    " (" + s->recipe_hash.substr(0, 12) + "), " + PopulationText(s->population);
    const ChartKind kind = req.subgroup > 1 ? ChartKind::kXbarR : ChartKind::kIMr;
    for (auto& p : ChartPanels(*s, kind, req.subgroup, req.rules, req.baseline))
      chart.panels.push_back(std::move(p));
    for (auto& p : ChartPanels(*s, ChartKind::kHistogram, 1, req.rules))
      chart.panels.push_back(std::move(p));
  }
  if (chart.panels.empty())
    throw std::runtime_error("--plot: no production test in the window measured " +
                             std::string(analysis::names::kResonanceFHz) + " or " +
                             std::string(analysis::names::kResonanceQ));
  io::WriteChart(path, chart);
}

// Serials with more than one test in the request's window (gauge candidates), most tests
// first, at most `most`: "G-1 (30 tests), G-2 (5 tests)".
std::string RepeatedSerials(db::Store& store, const StatsRequest& req, std::size_t most) {
  std::map<std::string, std::set<std::int64_t>> tests;
  for (const db::RecordKind kind : db::kAllRecordKinds) {
    db::MeasurementQuery q;
    q.from = req.from;
    q.to = req.to;
    q.recipe_hash = req.recipe_hash;
    q.kind = kind;
    for (const auto& r : store.MeasurementRows(q)) tests[r.serial].insert(r.test_id);
  }
  std::vector<std::pair<std::size_t, std::string>> repeated;
  for (const auto& [serial, ids] : tests)
    if (ids.size() > 1) repeated.emplace_back(ids.size(), serial);
  std::sort(repeated.begin(), repeated.end(), std::greater<>());
  if (repeated.empty()) return "none";
  std::string text;
  for (std::size_t i = 0; i < repeated.size() && i < most; ++i)
    text +=
        (i ? ", " : "") + repeated[i].second + " (" + std::to_string(repeated[i].first) + " tests)";
  if (repeated.size() > most) text += ", ...";
  return text;
}

// --gauge names a serial with measured tests, --reference only measurements of its study;
// else an error naming the known ones (exit 2).
void CheckGauge(db::Store& store, const StatsRequest& req, const nlohmann::json& report) {
  if (!req.gauge_serial) {
    if (!req.reference.empty()) throw std::runtime_error("--reference needs --gauge SERIAL");
    return;
  }
  const nlohmann::json& g = report["gauge"];
  if (g["tests"].get<std::size_t>() == 0)
    throw std::runtime_error("--gauge " + *req.gauge_serial +
                             ": no PASS or FAIL test of this serial in the window; serials "
                             "tested more than once: " +
                             RepeatedSerials(store, req, 10));
  std::set<std::string> names;
  for (const auto& m : g["measurements"]) names.insert(m["name"].get<std::string>());
  for (const auto& [name, value] : req.reference) {
    if (names.count(name)) continue;
    std::string known;
    for (const std::string& n : names) known += (known.empty() ? "" : ", ") + n;
    throw std::runtime_error("--reference " + name + ": the gauge study of " + *req.gauge_serial +
                             " has no such measurement; it has: " + known);
  }
}

bool Given(const StatsArgs& a, const std::string& name) {
  return std::find(a.given.begin(), a.given.end(), name) != a.given.end();
}

// `--yield`: the yield report (station/reports/yield.h); the capability options do not apply.
int RunYield(const StatsArgs& a) {
  for (const char* other : {"--gauge", "--reference", "--gauge-sigma-span", "--drift-t",
                            "--population", "--baseline", "--subgroup"})
    if (Given(a, other))
      throw std::runtime_error(std::string(other) +
                               " is a capability option and does not apply to --yield");
  YieldRequest req;
  if (!a.recipe_hash.empty()) req.recipe_hash = a.recipe_hash;
  if (!a.from.empty()) req.from = IsoOption("--from", a.from);
  if (!a.to.empty()) req.to = IsoOption("--to", a.to);
  if (req.from && req.to && *req.from >= *req.to)
    throw std::runtime_error("--from must be before --to");
  if (!ParseYieldGrouping(a.by, &req.options.by))
    throw std::runtime_error("--by must be all, shift, day or recipe (have '" + a.by + "')");
  std::string why;
  if (!ParseShifts(a.shifts, &req.options.shifts, &why))
    throw std::runtime_error("--shifts: " + why);
  req.options.utc_offset_min = a.utc_offset_min;
  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  const nlohmann::json report = YieldReport(*store, req);
  if (!a.plot.empty())
    io::WriteChart(a.plot, ParetoChart(report["total"], "eol stats --yield: " + a.db));
  if (a.json)
    std::cout << report.dump(2) << std::endl;
  else
    std::cout << YieldText(report);
  if (!a.plot.empty() && !a.json) std::printf("Pareto chart written to %s\n", a.plot.c_str());
  return 0;
}

int RunStats(const StatsArgs& a) {
  if (a.yield) return RunYield(a);
  for (const char* yield_only : {"--by", "--shifts", "--utc-offset-min"})
    if (Given(a, yield_only)) throw std::runtime_error(std::string(yield_only) + " needs --yield");
  StatsRequest req;
  if (!a.recipe_hash.empty()) req.recipe_hash = a.recipe_hash;
  if (!a.from.empty()) req.from = IsoOption("--from", a.from);
  if (!a.to.empty()) req.to = IsoOption("--to", a.to);
  if (!a.gauge.empty()) req.gauge_serial = a.gauge;
  req.gauge.sigma_span = a.sigma_span;
  req.drift.alarm_t = a.drift_t;
  if (!ParsePopulation(a.population, &req.population))
    throw std::runtime_error("--population must be all or pass (have '" + a.population + "')");
  req.subgroup = a.subgroup;
  req.baseline = a.baseline;
  std::string why;
  for (const std::string& r : a.references)
    if (!ParseReference(r, req.reference, &why)) throw std::runtime_error("--reference: " + why);
  if (const std::string bad = ValidateStatsRequest(req); !bad.empty())
    throw std::runtime_error(bad);
  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  const nlohmann::json report = StatsReport(*store, req);
  CheckGauge(*store, req, report);
  if (!a.plot.empty()) WritePlot(*store, req, a.plot);
  if (a.json)
    std::cout << report.dump(2) << std::endl;
  else
    PrintText(report);
  if (!a.plot.empty() && !a.json) std::printf("charts written to %s\n", a.plot.c_str());
  return report["alarms"].empty() ? 0 : 1;
}

}  // namespace

void AddStatsCommand(CLI::App& app) {
  auto args = std::make_shared<StatsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stats",
      "Production statistics per recipe: n, mean, sd, Cp/Cpk (within-subgroup sigma) and\n"
      "Pp/Ppk (overall sd) of every measurement against its limits, over the PASS and FAIL\n"
      "units (or --population pass), control charts with limits from the first --baseline\n"
      "PASS units and run-rule alarms (rules 1-3, naming the serial), drift\n"
      "alarms (trend over the passing tests), and with --gauge a type-1 gauge study of one\n"
      "serial tested repeatedly. Self-check (master) tests are excluded. --plot draws the\n"
      "control charts and histograms of resonance_f_hz and resonance_q.\n"
      "Exit code 1 when a drift (trend) alarm fired; 2 when --gauge names a serial without\n"
      "tests in the window or --reference a measurement its study lacks.\n"
      "With --yield: first-pass and final yield, retests and the Pareto of reasons, in total\n"
      "and --by shift, day or recipe (station/reports/yield.h defines each figure); --plot draws\n"
      "the Pareto.");
  cmd->add_option("--db", args->db, "SQLite file of the station")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--recipe-hash", args->recipe_hash, "Only tests under this recipe SHA-256");
  cmd->add_option("--from", args->from, "ISO 8601 start (inclusive), e.g. 2026-11-01");
  cmd->add_option("--to", args->to, "ISO 8601 end (exclusive)");
  cmd->add_option("--gauge", args->gauge, "Serial of the part of a type-1 gauge study");
  cmd->add_option("--reference", args->references,
                  "Reference value of the gauge part, NAME=VALUE (repeatable): gives Cgk");
  cmd->add_option("--gauge-sigma-span", args->sigma_span, "6 (default) or 4 sigma convention");
  cmd->add_option("--drift-t", args->drift_t, "|t| of the trend slope that raises an alarm (4)");
  cmd->add_option("--population", args->population,
                  "Units of capability and control charts: all (default: PASS and FAIL) or pass")
      ->capture_default_str();
  cmd->add_option("--baseline", args->baseline,
                  "Control limits from the first N PASS units (every unit is charted against them)")
      ->check(Between(2, 100000))
      ->capture_default_str();
  cmd->add_option("--subgroup", args->subgroup,
                  "1 (default): I-MR, sigma within = MRbar/1.128; 2..10: X-bar/R subgroups of\n"
                  "consecutive units, sigma within = Rbar/d2");
  cmd->add_option("--plot", args->plot,
                  "Write the control charts and histograms with the limits (SVG, or PNG for .png)");
  cmd->add_flag(
      "--json", args->json,
      "One JSON object (station/reports/stats_report.h; with --yield station/reports/yield.h)");
  cmd->add_flag("--yield", args->yield,
                "Yield instead of capability: first-pass, first-verdict and final yield,\n"
                "retested units, tests per unit and the Pareto of reason codes");
  cmd->add_option("--by", args->by, "--yield per: all (default), shift, day or recipe")
      ->capture_default_str();
  cmd->add_option("--shifts", args->shifts,
                  "--yield --by shift: NAME=HH:MM start times in local time, each shift\n"
                  "running until the next")
      ->capture_default_str();
  cmd->add_option("--utc-offset-min", args->utc_offset_min,
                  "--yield: local time = UTC + this many minutes (default: the time zone\n"
                  "of this machine, with its daylight saving rules)")
      ->check(Between(-840, 840));
  cmd->callback([args, cmd] {
    for (const CLI::Option* o : cmd->get_options())
      if (o->count() > 0) args->given.push_back(o->get_name());
    RunGuarded("stats", [&] { return RunStats(*args); });
  });
}

}  // namespace eol::station::cli
