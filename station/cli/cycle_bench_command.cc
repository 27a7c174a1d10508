// `eol cycle-bench`: a recipe against today's reference recipe on the same simulated units
// (station/bench/cycle_bench.h): excitation and cycle time, sigma(f0) and verdict agreement.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <cstdio>
#include <iostream>

#include "station/bench/cycle_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/data_files.h"

namespace eol::station::cli {
namespace {

void PrintRecipe(const char* label, const CycleBenchRecipe& c) {
  std::printf("%-9s %s: %s\n", label, c.recipe.c_str(), c.excitation.c_str());
  std::printf(
      "          excitation %.3f s, serial to verdict %.3f s, overhead %.3f s (medians per "
      "unit); sigma(f0) %.4f Hz\n",
      c.excitation_s, c.cycle_s, c.overhead_s, c.f0_sigma_hz);
  std::printf(
      "          %d units: %d PASS, %d FAIL, %d ERROR; %d of %d defective caught, %d good "
      "rejected; %d extended (sequential)\n",
      c.units, c.pass, c.fail, c.error, c.caught, c.defective, c.false_rejects, c.extended);
}

}  // namespace

void AddCycleBenchCommand(CLI::App& app) {
  auto o = std::make_shared<CycleBenchOptions>();
  o->recipe_path = DefaultRecipePath("pmsm-10pole-fast.json");
  o->reference_path = DefaultRecipePath();
  auto json = std::make_shared<bool>(false);
  CLI::App* cmd = app.add_subcommand(
      "cycle-bench",
      "Benchmark: a recipe (default: the 0.5 s variant) against the shipped recipe on the same\n"
      "simulated units (simulated clamp with its own timing, motor integrated from rest): median\n"
      "excitation and serial-to-verdict time, station overhead, sigma(f0), verdicts against the\n"
      "truth, outcome agreement and the ratios, measured in one run. Exit: 0 done, 1 could not\n"
      "run.");
  cmd->add_option("--recipe", o->recipe_path, "Recipe measured")->capture_default_str();
  cmd->add_option("--reference", o->reference_path, "The reference recipe (the shipped one)")
      ->capture_default_str();
  cmd->add_option("--units", o->units, "Simulated units (each tested with both recipes)")
      ->capture_default_str()
      ->check(Between(1, 100000));
  cmd->add_option("--seed", o->seed, "Seed of the simulated population")->capture_default_str();
  cmd->add_option("--defect-share", o->defect_share, "Share of poorly cemented rotors")
      ->capture_default_str()
      ->check(Between(0.0, 1.0));
  cmd->add_option("--time-scale", o->time_scale,
                  "Pace of the simulated excitation: 1 real time, 0 as fast as possible")
      ->capture_default_str()
      ->check(Between(0.0, 10.0));
  cmd->add_option("--sim", o->sim_model,
                  "time_domain (motor from rest, start transient) or steady_state")
      ->capture_default_str()
      ->check(CLI::IsMember({"time_domain", "steady_state"}));
  cmd->add_flag("--json", *json, "Print the figures as one JSON object");
  cmd->callback([o, json] {
    RunGuarded("cycle-bench", [&] {
      spdlog::set_level(spdlog::level::off);
      if (isatty(STDERR_FILENO))
        o->progress = [](const std::string& recipe, int done, int total) {
          std::fprintf(stderr, "\r%s: %d/%d units", recipe.c_str(), done, total);
          if (done == total) std::fprintf(stderr, "\n");
        };
      const CycleBenchResult r = RunCycleBench(*o);
      if (*json) {
        std::cout << ToJson(r).dump(2) << std::endl;
        return 0;
      }
      PrintRecipe("recipe", r.recipe);
      PrintRecipe("reference", r.reference);
      std::printf(
          "ratios recipe/reference: excitation %.3f, serial to verdict %.3f, sigma(f0) %.2f; "
          "same outcome on %.1f %% of the units, rms f0 difference %.4f Hz\n",
          r.excitation_ratio, r.cycle_ratio, r.f0_sigma_ratio, 100.0 * r.outcome_agreement,
          r.f0_rms_difference_hz);
      return 0;
    });
  });
}

}  // namespace eol::station::cli
