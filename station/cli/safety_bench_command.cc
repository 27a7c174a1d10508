// `eol safety-bench`: measures the watchdog's reaction time (fault reported by the fixture
// -> excitation relay open) on the simulated bench.
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "station/bench/safety_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/data_files.h"

namespace eol::station::cli {

void AddSafetyBenchCommand(CLI::App& app) {
  auto o = std::make_shared<SafetyBenchOptions>();
  o->recipe_path = DefaultRecipePath();
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "safety-bench",
      "Benchmark: reaction time from a fixture fault (clamp drop, low pressure, door, e-stop)\n"
      "during excitation to the excitation relay opening, with the real sequencer and watchdog\n"
      "on the simulated bench (real-time acquisition). Target: 50 ms.");
  cmd->add_option("--trials", o->trials_per_fault, "Tests per fault type")
      ->capture_default_str()
      ->check(Between(1, 10000));
  cmd->add_option("--seed", o->seed, "Seed of the fault times")->capture_default_str();
  cmd->add_option("--watchdog-period-ms", o->watchdog_period_ms, "Interlock poll period")
      ->capture_default_str()
      ->check(Between(1.0, 50.0));
  cmd->add_option("--recipe", o->recipe_path, "Recipe JSON")->capture_default_str();
  cmd->add_option("--fixture", o->fixture,
                  "sim: in-process simulated fixture; modbus: the Modbus TCP driver to the "
                  "fixture emulator on 127.0.0.1 (the bus round trip included)")
      ->capture_default_str()
      ->check(CLI::IsMember({"sim", "modbus"}));
  cmd->add_flag("--json", *json, "Print the figures as JSON");
  cmd->callback([o, json] {
    RunGuarded("safety-bench", [&] {
      spdlog::set_level(spdlog::level::off);
      const auto stats = RunSafetyBench(*o);
      if (*json) {
        std::cout << ToJson(stats).dump(2) << std::endl;
        return 0;
      }
      std::printf(
          "fixture %s, watchdog period %.1f ms; reaction = relay open - fault visible\n"
          "(station_stops: relay open - the station's last station_alive write; ERROR = relays "
          "the controller opened by itself)\n",
          o->fixture.c_str(), o->watchdog_period_ms);
      std::printf("%-13s %6s %6s %8s %8s %8s %8s\n", "fault", "tests", "ERROR", "min ms", "median",
                  "p95", "max");
      for (const auto& s : stats)
        std::printf("%-13s %6d %6d %8.2f %8.2f %8.2f %8.2f\n", s.fault.c_str(), s.trials, s.errors,
                    s.min_ms, s.median_ms, s.p95_ms, s.max_ms);
      return 0;
    });
  });
}

}  // namespace eol::station::cli
