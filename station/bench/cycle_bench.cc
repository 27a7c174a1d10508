#include "station/bench/cycle_bench.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <vector>

#include "analysis/qc/measurement_names.h"
#include "analysis/qc/statistics.h"
#include "analysis/text.h"
#include "drivers/factory/factory.h"
#include "station/daemon/cycle_time.h"
#include "station/daemon/station.h"

namespace eol::station {
namespace {

struct UnitResult {
  analysis::Outcome outcome = analysis::Outcome::kError;
  double f0_hz = std::nan("");
};

// Tests every serial on a station running `recipe_path`; fills `summary` and returns the
// per-serial results.
std::map<std::string, UnitResult> RunRecipe(const CycleBenchOptions& o,
                                            const std::string& recipe_path,
                                            const std::filesystem::path& dir,
                                            CycleBenchRecipe& summary) {
  const nlohmann::json sim = {{"population", {{"defect_share", o.defect_share}, {"seed", o.seed}}}};
  const nlohmann::json cfg = {
      {"station_id", "cycle-bench"},
      {"recipe", recipe_path},
      {"db", (dir / "records.sqlite").string()},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}, {"time_scale", o.time_scale}, {"model", o.sim_model}}},
      {"sim", sim}};
  StationConfig config = ParseStationConfig(cfg, "cycle-bench", "");
  // The bench made here, so the truth of each unit (its part) can be read after its test.
  auto bench = std::make_shared<drivers::SimBench>(
      drivers::ParseSimBenchSettings(io::JsonObject(sim, "/sim")));
  drivers::DriverSet drivers = drivers::MakeDrivers(config.drivers, bench);
  Station station(std::move(config), std::move(drivers));
  const Recipe& recipe = *station.recipe();
  summary.recipe = recipe.id + " v" + std::to_string(recipe.version);
  summary.excitation = analysis::Fixed(recipe.excitation.line_spacing_hz, 2) + " Hz lines, " +
                       std::to_string(recipe.transient_periods) + " + " +
                       std::to_string(recipe.periods) + " periods, " +
                       analysis::ToString(recipe.analysis.frf_method) + ", " +
                       std::to_string(recipe.phase_pairs.size()) + " phase pair(s)";
  std::vector<double> excitation, cycle, overhead, sigma;
  std::map<std::string, UnitResult> out;
  for (int i = 1; i <= o.units; ++i) {
    const std::string serial = "CB-" + std::to_string(o.seed) + "-" + std::to_string(i);
    const db::TestRecord r = station.RunTest(serial);
    const bool defective = bench->part() && bench->part()->defective;
    ++summary.units;
    summary.pass += r.outcome == analysis::Outcome::kPass;
    summary.fail += r.outcome == analysis::Outcome::kFail;
    summary.error += r.outcome != analysis::Outcome::kPass && r.outcome != analysis::Outcome::kFail;
    if (defective) {
      ++summary.defective;
      summary.caught += r.outcome == analysis::Outcome::kFail;
    } else {
      summary.false_rejects += r.outcome == analysis::Outcome::kFail;
    }
    const auto first = r.conditions.looks.find("");  // the first pair's (test_conditions.h)
    summary.extended += first != r.conditions.looks.end() && first->second.looks.value_or(1) > 1;
    excitation.push_back(CycleStepS(r.cycle_s, "excitation"));
    cycle.push_back(CycleStepS(r.cycle_s, "total"));
    overhead.push_back(StationOverheadS(r.cycle_s));
    UnitResult u;
    u.outcome = r.outcome;
    for (const auto& m : r.measurements)
      if (m.name == analysis::names::kResonanceFHz) {
        u.f0_hz = m.value;
        if (std::isfinite(m.sigma)) sigma.push_back(m.sigma);
      }
    out[serial] = u;
    if (o.progress) o.progress(summary.recipe, i, o.units);
  }
  summary.excitation_s = analysis::Median(excitation);
  summary.cycle_s = analysis::Median(cycle);
  summary.overhead_s = analysis::Median(overhead);
  summary.f0_sigma_hz = analysis::Median(sigma);
  return out;
}

}  // namespace

bool CycleBenchOptions::IsValid(std::string* why) const {
  if (units < 1 || units > 100000) {
    *why = "units must be in [1, 100000]";
  } else if (!(defect_share >= 0.0 && defect_share <= 1.0)) {
    *why = "defect_share must be in [0, 1]";
  } else if (!(time_scale >= 0.0 && time_scale <= 10.0)) {
    *why = "time_scale must be in [0, 10]";
  } else if (sim_model != "time_domain" && sim_model != "steady_state") {
    *why = "sim_model must be time_domain or steady_state";
  } else {
    return true;
  }
  return false;
}

CycleBenchResult RunCycleBench(const CycleBenchOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("cycle-bench: " + why);
  const std::filesystem::path root =
      std::filesystem::temp_directory_path() / ("eol-cycle-bench-" + std::to_string(::getpid()));
  std::filesystem::remove_all(root);
  std::filesystem::create_directories(root / "recipe");
  std::filesystem::create_directories(root / "reference");
  CycleBenchResult r;
  std::map<std::string, UnitResult> a, b;
  try {
    b = RunRecipe(o, o.reference_path, root / "reference", r.reference);
    a = RunRecipe(o, o.recipe_path, root / "recipe", r.recipe);
  } catch (...) {
    std::filesystem::remove_all(root);
    throw;
  }
  std::filesystem::remove_all(root);
  int same = 0, both = 0;
  double sum2 = 0;
  for (const auto& [serial, u] : a) {
    const UnitResult& v = b.at(serial);
    same += u.outcome == v.outcome;
    if (std::isfinite(u.f0_hz) && std::isfinite(v.f0_hz)) {
      sum2 += (u.f0_hz - v.f0_hz) * (u.f0_hz - v.f0_hz);
      ++both;
    }
  }
  r.outcome_agreement = static_cast<double>(same) / static_cast<double>(a.size());
  r.f0_rms_difference_hz = both > 0 ? std::sqrt(sum2 / both) : std::nan("");
  r.excitation_ratio = r.recipe.excitation_s / r.reference.excitation_s;
  r.cycle_ratio = r.recipe.cycle_s / r.reference.cycle_s;
  r.f0_sigma_ratio = r.recipe.f0_sigma_hz / r.reference.f0_sigma_hz;
  return r;
}

nlohmann::json ToJson(const CycleBenchResult& r) {
  const auto recipe = [](const CycleBenchRecipe& c) {
    return nlohmann::json{{"recipe", c.recipe},
                          {"excitation", c.excitation},
                          {"units", c.units},
                          {"pass", c.pass},
                          {"fail", c.fail},
                          {"error", c.error},
                          {"defective", c.defective},
                          {"caught", c.caught},
                          {"false_rejects", c.false_rejects},
                          {"extended", c.extended},
                          {"excitation_s", c.excitation_s},
                          {"cycle_s", c.cycle_s},
                          {"overhead_s", c.overhead_s},
                          {"f0_sigma_hz", c.f0_sigma_hz}};
  };
  return {{"recipe", recipe(r.recipe)},
          {"reference", recipe(r.reference)},
          {"outcome_agreement", r.outcome_agreement},
          {"f0_rms_difference_hz", r.f0_rms_difference_hz},
          {"excitation_ratio", r.excitation_ratio},
          {"cycle_ratio", r.cycle_ratio},
          {"f0_sigma_ratio", r.f0_sigma_ratio}};
}

}  // namespace eol::station
