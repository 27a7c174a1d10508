// Cycle-time benchmark (issue 16, `eol cycle-bench`): a recipe against a reference recipe (the
// shipped one) on the same simulated units, measured in one run.
//
// Each recipe tests the same serials (the simulated population draws a unit from its serial:
// the same serial is the same motor, good or with a soft bond) on its own station: the
// simulated fixture with its own clamp timing, the simulated DAQ playing the excitation into
// the motor integrated in the time domain FROM REST (start transient included;
// drivers/sim/sim_daq.h time_domain), paced at time_scale (1: real time), a fresh SQLite file
// per recipe. Per recipe it reports the medians per unit of the excitation (all phase pairs),
// serial-to-verdict time and station overhead (station/daemon/cycle_time.h), the median reported
// sigma of f0, the verdicts against the simulator's truth (defective caught, good rejected),
// and across the two: the share of units with the same outcome, the rms of the f0 difference,
// and the ratios recipe / reference of excitation, cycle and sigma(f0).
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

namespace eol::station {

struct CycleBenchOptions {
  std::string recipe_path;     // the recipe measured
  std::string reference_path;  // the reference (the shipped recipe)
  int units = 20;
  std::uint64_t seed = 1;                 // of the simulated population
  double defect_share = 0.2;              // share of soft-bond rotors
  double time_scale = 1.0;                // 1: the excitation and the clamp in real time
  std::string sim_model = "time_domain";  // or "steady_state" (no start transient)
  std::function<void(const std::string& recipe, int done, int total)> progress;

  bool IsValid(std::string* why) const;
};

struct CycleBenchRecipe {
  std::string recipe;      // "<id> v<version>"
  std::string excitation;  // "4 Hz lines, 0 + 2 periods, transient_lpm"
  int units = 0, pass = 0, fail = 0, error = 0;
  int defective = 0, caught = 0, false_rejects = 0;
  int extended = 0;  // units that took more than one look (a sequential recipe)
  double excitation_s = 0, cycle_s = 0, overhead_s = 0;  // medians per unit
  double f0_sigma_hz = 0;                                // median reported sigma of f0
};

struct CycleBenchResult {
  CycleBenchRecipe recipe, reference;
  double outcome_agreement = 0;  // share of units with the same outcome
  double f0_rms_difference_hz = 0;
  double excitation_ratio = 0, cycle_ratio = 0, f0_sigma_ratio = 0;  // recipe / reference
};

// Throws std::invalid_argument for invalid options, std::runtime_error (naming the file)
// when a recipe does not load.
CycleBenchResult RunCycleBench(const CycleBenchOptions& options);
nlohmann::json ToJson(const CycleBenchResult& r);

}  // namespace eol::station
