// `eol demo`: the station on its simulators, testing a population of simulated motors with a
// known share of poorly cemented rotors, and scoring its verdicts against the truth.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "analysis/qc/measurement_names.h"
#include "analysis/qc/statistics.h"
#include "analysis/text.h"
#include "drivers/emulators/modbus_fixture_server.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/cycle_time.h"
#include "station/daemon/data_files.h"
#include "station/daemon/station.h"
#include "station/daemon/status_board.h"

namespace eol::station::cli {
namespace {

struct DemoArgs {
  int units = 20;
  std::string db = "eol-demo.sqlite";
  // The recipe designed for time (issue 16): the 5 s recipe's information in 0.474 s.
  std::string recipe = DefaultRecipePath("pmsm-10pole-fast.json");
  bool json = false;
  int port = 8080;
  std::string listen = "127.0.0.1";
  std::uint64_t seed = 1;
  double defect_share = 0.2;
  double time_scale = 0.0;
  bool verbose = false;
  bool publish_before_release = false;
  bool init_store = false;
  drivers::SimBenchSettings timing;  // the simulated fixture's clamp travel and heartbeat
  std::string fixture = "modbus";
  std::string sim = "time_domain";
};

double MeasurementValue(const db::TestRecord& r, std::string_view name) {
  for (const auto& m : r.measurements)
    if (m.name == name) return m.value;
  return std::nan("");
}

int RunDemo(const DemoArgs& a) {
  const nlohmann::json sim = {{"population", {{"defect_share", a.defect_share}, {"seed", a.seed}}},
                              {"clamp_close_s", a.timing.clamp_close_s},
                              {"clamp_open_s", a.timing.clamp_open_s},
                              {"heartbeat_period_s", a.timing.heartbeat_period_s}};
  nlohmann::json cfg = {
      {"station_id", "demo"},
      {"recipe", a.recipe},
      {"db", a.db},
      {"init_store", a.init_store},
      {"http", {{"listen", a.listen}, {"port", a.port}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}, {"time_scale", a.time_scale}, {"model", a.sim}}},
      {"sim", sim},
      {"publish_before_release", a.publish_before_release}};
  spdlog::set_level(a.verbose ? spdlog::level::info : spdlog::level::warn);
  // One simulated bench: the DAQ plays into its motor, and with --fixture modbus the station
  // reaches its clamp and interlocks over real Modbus TCP through the fixture emulator that
  // `eol fixture-sim` runs, on a free port of 127.0.0.1.
  auto bench = std::make_shared<drivers::SimBench>(
      drivers::ParseSimBenchSettings(io::JsonObject(sim, "/sim")));
  std::unique_ptr<drivers::ModbusFixtureServer> emulator;
  if (a.fixture == "modbus") {
    drivers::ModbusFixtureServerSettings es;
    es.link.transport = drivers::ModbusLink::Transport::kTcp;
    es.link.host = "127.0.0.1";
    es.link.port = 0;
    emulator = std::make_unique<drivers::ModbusFixtureServer>(bench, es);
    if (const drivers::Status s = emulator->Start(); !s.ok())
      throw std::runtime_error("fixture emulator: " + s.message());
    cfg["fixture"] = {{"driver", "modbus-tcp"},
                      {"host", "127.0.0.1"},
                      {"port", emulator->port()},
                      {"unit_id", 1}};
  }
  StationConfig config = ParseStationConfig(cfg, "demo", "");
  drivers::DriverSet drivers = drivers::MakeDrivers(config.drivers, bench);
  Station station(std::move(config), std::move(drivers));
  station.StartHttp(DefaultWebRoot());
  std::ostream& out = a.json ? std::cerr : std::cout;
  out << "eol demo: " << a.units << " simulated units, defect share " << a.defect_share
      << ", fixture "
      << (emulator ? "over Modbus TCP 127.0.0.1:" + std::to_string(emulator->port())
                   : std::string("in-process"))
      << ", recipe " << station.recipe()->id << " v" << station.recipe()->version << ", records in "
      << a.db << ", status at http://" << a.listen << ":" << station.http_port() << "/api/status\n";

  VerdictCounts counts;  // the demo reports an ABORTED unit with the ERRORs
  int defective = 0, detected = 0, false_rejects = 0;
  nlohmann::json serials = nlohmann::json::array();
  // Cycle time per unit (station/daemon/cycle_time.h): excitation of all phase pairs, serial
  // received -> verdict published, and the station's own overhead.
  std::vector<double> excitation_s, cycle_s, overhead_s;
  for (int i = 1; i <= a.units; ++i) {
    char serial[64];
    std::snprintf(serial, sizeof serial, "DEMO-%llu-%04d", static_cast<unsigned long long>(a.seed),
                  i);
    const db::TestRecord r = station.RunTest(serial);
    const bool is_defective = bench->part() && bench->part()->defective;
    serials.push_back(serial);
    excitation_s.push_back(CycleStepS(r.cycle_s, "excitation"));
    cycle_s.push_back(CycleStepS(r.cycle_s, "total"));
    overhead_s.push_back(StationOverheadS(r.cycle_s));
    counts.Add(r.outcome);
    if (is_defective) {
      ++defective;
      if (r.outcome == analysis::Outcome::kFail) ++detected;
    } else if (r.outcome == analysis::Outcome::kFail) {
      ++false_rejects;
    }
    char line[256];
    std::snprintf(line, sizeof line, "[%3d/%d] %-16s f0 = %7.2f Hz  %-7s truth: %-9s %5.2f s ", i,
                  a.units, serial, MeasurementValue(r, analysis::names::kResonanceFHz),
                  analysis::ToString(r.outcome), is_defective ? "defective" : "good",
                  CycleStepS(r.cycle_s, "total"));
    out << line << (r.reasons.empty() ? "" : r.reasons.front().text) << "\n" << std::flush;
  }
  const std::uint64_t error = counts.error + counts.aborted;
  out << "summary: " << a.units << " units: " << counts.pass << " PASS, " << counts.fail
      << " FAIL, " << error << " ERROR; " << detected << " of " << defective
      << " defective rotors caught, " << false_rejects << " good rotors rejected\n"
      << "cycle (medians per unit): excitation "
      << analysis::Fixed(analysis::Median(excitation_s), 3) << " s, serial to verdict "
      << analysis::Fixed(analysis::Median(cycle_s), 3) << " s, station overhead "
      << analysis::Fixed(analysis::Median(overhead_s), 3) << " s (time scale " << a.time_scale
      << ")\n";
  if (a.json) {
    const nlohmann::json summary = {{"units", a.units},
                                    {"pass", counts.pass},
                                    {"fail", counts.fail},
                                    {"error", error},
                                    {"defective", defective},
                                    {"detected", detected},
                                    {"false_rejects", false_rejects},
                                    {"serials", serials},
                                    {"excitation_s", analysis::Median(excitation_s)},
                                    {"cycle_s", analysis::Median(cycle_s)},
                                    {"overhead_s", analysis::Median(overhead_s)},
                                    {"time_scale", a.time_scale},
                                    {"db", a.db},
                                    {"http_port", station.http_port()}};
    std::cout << summary.dump() << std::endl;
  }
  return 0;
}

}  // namespace

void AddDemoCommand(CLI::App& app) {
  auto args = std::make_shared<DemoArgs>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "Run the station on its simulated fixture and motor: test N simulated units drawn from a\n"
      "population with a known share of poorly cemented rotors, store every record, serve the\n"
      "JSON status while running, and score the verdicts against the simulator's truth.");
  cmd->add_option("--units", args->units, "Number of simulated units to test")
      ->capture_default_str()
      ->check(Between(1, 1000000));
  cmd->add_option("--db", args->db,
                  "SQLite file for the records (created if missing; an existing file must be a "
                  "store)")
      ->capture_default_str();
  cmd->add_option("--recipe", args->recipe, "Recipe JSON")->capture_default_str();
  cmd->add_flag("--json", args->json,
                "Print the summary as one JSON object on stdout (unit lines go to stderr)");
  cmd->add_option("--port", args->port, "HTTP port for the JSON status (0: any free port)")
      ->capture_default_str()
      ->check(Between(0, 65535));
  cmd->add_option("--listen", args->listen, "HTTP listen address")->capture_default_str();
  cmd->add_option("--seed", args->seed, "Seed of the simulated population")->capture_default_str();
  cmd->add_option("--defect-share", args->defect_share,
                  "Share of poorly cemented rotors in the population")
      ->capture_default_str()
      ->check(Between(0.0, 1.0));
  cmd->add_option("--time-scale", args->time_scale,
                  "Pace of the simulated acquisition: 1 real time, 0 as fast as possible")
      ->capture_default_str()
      ->check(Between(0.0, 10.0));
  cmd->add_option(
         "--fixture", args->fixture,
         "modbus: the station talks Modbus TCP to the fixture emulator (eol fixture-sim's\n"
         "server) on 127.0.0.1; sim: the in-process simulated fixture")
      ->capture_default_str()
      ->check(CLI::IsMember({"modbus", "sim"}));
  cmd->add_option("--sim", args->sim,
                  "Simulated motor: time_domain (integrated from rest, start transient\n"
                  "included, as a real motor) or steady_state (no transient, faster)")
      ->capture_default_str()
      ->check(CLI::IsMember({"time_domain", "steady_state"}));
  cmd->add_option("--clamp-close-s", args->timing.clamp_close_s,
                  "Simulated clamp: command to clamped sensor")
      ->capture_default_str();
  cmd->add_option("--clamp-open-s", args->timing.clamp_open_s,
                  "Simulated clamp: command to released sensor")
      ->capture_default_str();
  cmd->add_option("--heartbeat-period-s", args->timing.heartbeat_period_s,
                  "Simulated controller: heartbeat increment period")
      ->capture_default_str();
  cmd->add_flag("--publish-before-release", args->publish_before_release,
                "Store and publish each verdict while the clamp opens (the station config's "
                "publish_before_release)");
  cmd->add_flag("--verbose", args->verbose, "Log every sequencer state (to stderr)");
  cmd->add_flag("--init-store", args->init_store,
                "Make an existing empty file (0 bytes) at --db a new store");
  cmd->callback([args] { RunGuarded("demo", [&] { return RunDemo(*args); }); });
}

}  // namespace eol::station::cli
