// `eol detectability --recipe R [--motor M.json] [--gap gap.json | --k-fixture K]
//                    [--golden FILES...] [--json]`:
// where each defect class shows in the real fixture and whether the recipe's measurement can
// tell it from good units (analysis/qc/detectability.h), on the recipe's motor (--motor: its
// motor JSON) or the built-in ten-pole chain; a model whose good rotor misses the recipe's f0
// by more than 15 % is refused (DetectabilityModelMismatch), never predicted silently. The fixture
// stiffness comes from the gap diagnosis (`eol gap --json`: params.k_fixture_nm_per_rad of
// fixture_compliance) or
// --k-fixture, and is applied as the chain's fixture spring; without either the chain's
// default fixture is used. The good units' spread comes from --golden (standard deviation of
// each measurement), else from the recipe's two-sided limits taken as +-limit_sigmas.
// Exit: 0 analysed (warnings on stdout), 1 not analysable, 2 usage/file error.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "analysis/qc/detectability.h"
#include "analysis/text.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/golden_inputs.h"
#include "station/daemon/data_files.h"
#include "station/daemon/qc_service.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct DetectArgs {
  std::string recipe = DefaultRecipePath();
  std::string motor;
  std::string gap;
  double k_fixture = 0.0;
  std::vector<std::string> golden;
  double limit_sigmas = 3.0;
  double required_sigmas = 3.0;
  bool json = false;
};

double KFixtureFromGap(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be read");
  json j;
  try {
    j = json::parse(in);
  } catch (const json::exception& e) {
    throw std::runtime_error(path + ": not JSON: " + e.what());
  }
  const json* p = j.contains("params") ? &j.at("params") : nullptr;
  if (!p || !p->contains("k_fixture_nm_per_rad") || !p->at("k_fixture_nm_per_rad").is_number())
    throw std::runtime_error(path +
                             ": /params/k_fixture_nm_per_rad is missing: the gap diagnosis "
                             "did not name fixture_compliance (effect: " +
                             j.value("effect", std::string("?")) + "); give --k-fixture");
  const double k = p->at("k_fixture_nm_per_rad").get<double>();
  if (!(k > 0.0 && std::isfinite(k)))
    throw std::runtime_error(path + ": /params/k_fixture_nm_per_rad must be positive");
  return k;
}

std::map<std::string, double> SpreadFromGolden(const std::vector<analysis::GoldenUnit>& units) {
  std::map<std::string, std::vector<double>> v;
  for (const auto& u : units)
    for (const auto& [name, x] : u.values) v[name].push_back(x);
  std::map<std::string, double> sd;
  for (const auto& [name, xs] : v) {
    if (xs.size() < 3) continue;
    double m = 0.0, ss = 0.0;
    for (double x : xs) m += x;
    m /= static_cast<double>(xs.size());
    for (double x : xs) ss += (x - m) * (x - m);
    sd[name] = std::sqrt(ss / static_cast<double>(xs.size() - 1));
  }
  return sd;
}

std::string G(double v) { return analysis::Significant(v, 4); }

int RunDetect(const DetectArgs& a) {
  if (!a.gap.empty() && a.k_fixture > 0.0)
    throw std::runtime_error("give either --gap or --k-fixture, not both");
  const Recipe r = LoadRecipe(a.recipe);
  std::string source = "the chain's default fixture";
  double k_fixture = 0.0;
  if (!a.gap.empty()) {
    k_fixture = KFixtureFromGap(a.gap);
    source = "gap diagnosis " + a.gap;
  } else if (a.k_fixture > 0.0) {
    k_fixture = a.k_fixture;
    source = "--k-fixture";
  }
  std::optional<io::MotorSpec> motor;
  if (!a.motor.empty()) motor = io::LoadMotorJson(a.motor);
  analysis::DetectabilityOptions o = DetectabilityOptionsFor(
      r, motor ? &*motor : nullptr, k_fixture, a.limit_sigmas, a.required_sigmas);
  if (const std::string why = DetectabilityModelMismatch(r, motor ? &*motor : nullptr);
      !why.empty()) {
    std::cerr << "eol detectability: " << why << std::endl;
    if (a.json) std::cout << json{{"usable", false}, {"error", why}}.dump() << std::endl;
    return 1;
  }
  std::string spread_source = "the recipe's limits as +-" + G(a.limit_sigmas) + " sigma";
  if (!a.golden.empty()) {
    std::vector<std::string> skipped;
    const std::vector<analysis::GoldenUnit> golden = ReadGoldenUnits(a.golden, r, &skipped);
    o.unit_spread = SpreadFromGolden(golden);
    o.spread_units = static_cast<int>(golden.size());
    spread_source = std::to_string(a.golden.size()) + " golden file(s)";
  }
  const analysis::DetectabilitySummary s = analysis::PredictDetectability(o);
  if (!s.usable) {
    std::cerr << "eol detectability: " << s.message << std::endl;
    if (a.json) std::cout << json{{"usable", false}, {"error", s.message}}.dump() << std::endl;
    return 1;
  }
  if (a.json) {
    json j = DetectabilityJson(s, source, spread_source, a.required_sigmas);
    json pod = json::array();
    for (const auto& p : s.pod) {
      json points = json::array();
      for (const auto& pt : p.points)
        points.push_back(
            {{"loss", pt.loss},
             {"pod", pt.pod},
             {"pod_lower", std::isnan(pt.pod_lower) ? json(nullptr) : json(pt.pod_lower)},
             {"f0_hz", pt.f0_hz},
             {"best", pt.best}});
      pod.push_back({{"name", p.name},
                     {"a90", std::isnan(p.a90) ? json(nullptr) : json(p.a90)},
                     {"a90_95", std::isnan(p.a90_95) ? json(nullptr) : json(p.a90_95)},
                     {"points", points}});
    }
    j["pod"] = pod;
    std::cout << j.dump() << std::endl;
    return 0;
  }
  std::cout << "detectability (" << r.id << " v" << r.version << "): " << s.message << "\n"
            << "fixture from " << source << "; good-unit spread from " << spread_source << "\n";
  std::printf("%-18s %8s %6s %8s %9s  %-16s %6s  %s\n", "defect", "f0 Hz", "Q", "chi2/dof",
              "curve S", "best", "sep", "recommended limit (miss)");
  for (const auto& c : s.classes) {
    std::string rec = "-";
    for (const auto& m : c.measurements)
      if (m.name == c.best)
        rec = std::string(m.limit_is_lo ? "lo " : "hi ") + G(m.recommended_limit) + " (" +
              G(100.0 * m.miss_probability) + " % pass)";
    std::printf("%-18s %8.2f %6.1f %8.3f %9.1f  %-16s %6.1f  %s\n", c.defect.c_str(), c.f0_hz, c.q,
                c.chi2_per_dof, c.curve_separation, c.best.c_str(), c.best_separation, rec.c_str());
  }
  std::cout << "model POD against the bond stiffness loss a (best measurement at its "
               "recommended limit); a90/95 "
            << (o.spread_units >= 2 ? "with the good-unit spread at its 95 % upper bound from " +
                                          std::to_string(o.spread_units) + " golden units"
                                    : std::string("needs the spread from golden units (--golden)"))
            << "; the model's own error: eol production-bench / eol pod:\n";
  for (const auto& p : s.pod) {
    std::cout << "  " << p.name << ": a90 "
              << (std::isnan(p.a90) ? std::string("not reached") : G(p.a90)) << ", a90/95 "
              << (std::isnan(p.a90_95) ? std::string("-") : G(p.a90_95)) << ";";
    for (const auto& pt : p.points)
      std::cout << " " << G(pt.loss) << ":" << G(pt.pod) << (pt.best == "fit (ERROR)" ? "E" : "");
    std::cout << "\n";
  }
  for (const auto& c : s.classes) {
    if (c.separable) continue;
    std::cout << "WARNING: " << c.defect << " cannot be told apart from good units with this "
              << "fixture and excitation (best " << c.best << ", " << G(c.best_separation)
              << " sigma < " << G(a.required_sigmas) << ")\n";
    for (const auto& rem : c.remedies) std::cout << "  - " << rem << "\n";
  }
  return 0;
}

}  // namespace

void AddDetectabilityCommand(CLI::App& app) {
  auto args = std::make_shared<DetectArgs>();
  CLI::App* cmd = app.add_subcommand(
      "detectability",
      "Predict where each defect class (one, two, half, all soft magnets; weak bonds at 0.1-0.9\n"
      "of their stiffness) shows in the real fixture, compare it with the good units' spread\n"
      "and the measurement's sigma, report the separation and the recommended limit, and warn\n"
      "with a remedy (stiffer clamp, longer measurement, another phase pair) when a class\n"
      "cannot be told apart. Exit: 0 analysed, 1 not analysable, 2 usage or file error.");
  cmd->add_option("--recipe", args->recipe, "Recipe: excitation, analysis, limits")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  cmd->add_option("--motor", args->motor,
                  "The recipe's motor JSON (recipes/motors/): its winding, transmission and "
                  "rotor chain; default: the built-in ten-pole chain, refused for a recipe whose "
                  "f0 it misses by more than 15 %")
      ->check(CLI::ExistingFile);
  cmd->add_option("--gap", args->gap, "`eol gap --json` output with fixture_compliance")
      ->check(CLI::ExistingFile);
  cmd->add_option("--k-fixture", args->k_fixture, "Fixture stiffness, N m/rad")->check(Positive());
  cmd->add_option("--golden", args->golden, "Good units for the spread (as `eol teach`)");
  cmd->add_option("--limit-sigmas", args->limit_sigmas,
                  "Without --golden: the recipe's limits are taken as +- this many sigma")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--required-sigmas", args->required_sigmas, "Separation needed")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("detectability", [&] { return RunDetect(*args); }); });
}

}  // namespace eol::station::cli
