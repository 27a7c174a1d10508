// `eol stats --db FILE [--recipe-hash H] [--from T] [--to T] [--gauge SERIAL]
//  [--reference NAME=VALUE ...] [--gauge-sigma-span 6|4] [--drift-t T] [--json]`:
// capability, drift alarms and the type-1 gauge study (station/stats_report.h).
// Exit 0 when no drift alarm fired, 1 when one did, 2 on usage or file errors.
#include <cstdio>
#include <iostream>

#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/stats_report.h"

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
  bool json = false;
};

std::string Num(const nlohmann::json& v, const char* fmt = "%.4g") {
  if (!v.is_number()) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, fmt, v.get<double>());
  return buf;
}

void PrintText(const nlohmann::json& r) {
  for (const auto& g : r["recipes"]) {
    std::printf("recipe %s v%d (%s): %zu production tests\n",
                g["recipe_id"].get<std::string>().c_str(), g["recipe_version"].get<int>(),
                g["recipe_hash"].get<std::string>().substr(0, 12).c_str(),
                g["tests"].get<std::size_t>());
    std::printf("  %-34s %6s %12s %10s %8s %8s  %s\n", "measurement", "n", "mean", "sd", "Cp",
                "Cpk", "drift");
    for (const auto& m : g["measurements"])
      std::printf("  %-34s %6zu %12s %10s %8s %8s  %s\n", m["name"].get<std::string>().c_str(),
                  m["n"].get<std::size_t>(), Num(m["mean"], "%.6g").c_str(), Num(m["sd"]).c_str(),
                  Num(m["cp"], "%.3f").c_str(), Num(m["cpk"], "%.3f").c_str(),
                  m["drift"]["alarm"].get<bool>() ? "ALARM" : "-");
  }
  if (r["recipes"].empty()) std::printf("no production tests in the window\n");
  for (const auto& a : r["alarms"]) std::printf("ALARM %s\n", a.get<std::string>().c_str());
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

int RunStats(const StatsArgs& a) {
  StatsRequest req;
  if (!a.recipe_hash.empty()) req.recipe_hash = a.recipe_hash;
  if (!a.from.empty()) req.from = IsoOption("--from", a.from);
  if (!a.to.empty()) req.to = IsoOption("--to", a.to);
  if (!a.gauge.empty()) req.gauge_serial = a.gauge;
  req.gauge.sigma_span = a.sigma_span;
  req.drift.alarm_t = a.drift_t;
  std::string why;
  for (const std::string& r : a.references)
    if (!ParseReference(r, req.reference, &why)) throw std::runtime_error("--reference: " + why);
  if (const std::string bad = ValidateStatsRequest(req); !bad.empty())
    throw std::runtime_error(bad);
  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  const nlohmann::json report = StatsReport(*store, req);
  if (a.json)
    std::cout << report.dump(2) << std::endl;
  else
    PrintText(report);
  return report["alarms"].empty() ? 0 : 1;
}

}  // namespace

void AddStatsCommand(CLI::App& app) {
  auto args = std::make_shared<StatsArgs>();
  CLI::App* cmd = app.add_subcommand(
      "stats",
      "Production statistics per recipe: n, mean, sd, Cp, Cpk of every measurement against\n"
      "its limits, drift alarms (trend over the passing tests), and with --gauge a type-1\n"
      "gauge study of one serial tested repeatedly. Self-check (master) tests are excluded.\n"
      "Exit code 1 when a drift alarm fired.");
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
  cmd->add_flag("--json", args->json, "One JSON object (station/stats_report.h)");
  cmd->callback([args] { RunGuarded("stats", [&] { return RunStats(*args); }); });
}

}  // namespace eol::station::cli
