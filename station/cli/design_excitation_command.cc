// `eol design-excitation --recipe R [--sigma-f0-hz S] [--out R2]`: the shortest excitation that
// meets the recipe's "excitation_design" requirement (analysis/signal/excitation_design.h).
// Prints every candidate line grid with its amplitude, what limits it, the periods it needs and
// the bound it reaches; with --out writes R with the chosen excitation (spacing, peak, periods
// played from rest and analysed whole by the transient-aware estimator), the excitation condition
// windows scaled with the amplitude, version + 1, as a proposal an engineer approves (as teach).
// Exit: 0 designed, 1 no excitation meets the requirement, 2 usage or file error.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/text.h"
#include "db/clock.h"
#include "drivers/io/json_config.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/recipe.h"
#include "station/daemon/recipe_design.h"

namespace eol::station::cli {
namespace {

using analysis::Fixed;
using nlohmann::json;

struct DesignArgs {
  std::string recipe;
  double sigma_f0_hz = 0.0;  // 0: the recipe's
  std::string crest_for;     // empty: the recipe's
  std::string out;
  bool force = false;
  bool json = false;
};

json CandidateJson(const analysis::ExcitationCandidate& c) {
  return {{"line_spacing_hz", c.line_spacing_hz},
          {"lines", c.lines},
          {"peak_v", c.peak_v},
          {"amplitude_limited_by", c.amplitude_limited_by},
          {"v_rms", c.v_rms},
          {"a_rms", c.a_rms},
          {"current_peak_a", c.current_peak_a},
          {"periods", c.periods},
          {"record_s", c.record_s},
          {"sigma_f0_hz", c.sigma_f0_hz},
          {"meets", c.meets}};
}

void Scale(analysis::Limit& window, double factor) {
  if (window.lo) *window.lo *= factor;
  if (window.hi) *window.hi *= factor;
}

// The recipe with the designed excitation, as a proposal.
// The rms windows follow the rms the new excitation drives against what the recipe's own
// (`own`) drove: the crest factor may differ, so the peak ratio would not do.
Recipe Designed(const Recipe& recipe, const analysis::ExcitationDesign& d,
                const analysis::ExcitationRequirement& requirement,
                const analysis::ExcitationDrive& own) {
  Recipe next = WithDesignedExcitation(recipe, d);
  Scale(next.conditions.excitation_v_rms, d.chosen.v_rms / own.v_rms);
  Scale(next.conditions.excitation_a_rms, d.chosen.a_rms / own.a_rms);
  next.excitation_design = requirement;
  next.version = recipe.version + 1;
  next.description = recipe.description + " [eol design-excitation: std(f0) " +
                     Fixed(d.chosen.sigma_f0_hz, 4) + " Hz at the nominal motor in " +
                     Fixed(d.chosen.record_s, 3) + " s, " + Fixed(d.chosen.line_spacing_hz, 4) +
                     " Hz lines, " + Fixed(d.chosen.peak_v, 2) + " V peak]";
  next.approval = RecipeApproval{"proposed", "eol design-excitation", db::UtcNowIso8601(), ""};
  return next;
}

int RunDesign(const DesignArgs& a) {
  // The recipe as it is (its own excitation, for comparison), and as designed (--crest-for).
  const nlohmann::json original = io::ReadJsonFile(a.recipe);
  const Recipe as_is = ParseRecipe(original, a.recipe, {.check_excitation_design = false});
  const Recipe recipe = [&] {
    if (a.crest_for.empty()) return as_is;
    nlohmann::json source = original;
    if (source.contains("excitation") && source["excitation"].is_object())
      source["excitation"]["crest_for"] = a.crest_for;
    return ParseRecipe(source, a.recipe, {.check_excitation_design = false});
  }();
  if (!recipe.excitation_design)
    throw std::runtime_error(a.recipe +
                             ": has no \"excitation_design\" block (the required std(f0), the "
                             "nominal motor, the DAQ's noise and the amplitude limits; "
                             "station/daemon/recipe.h)");
  analysis::ExcitationRequirement requirement = *recipe.excitation_design;
  if (a.sigma_f0_hz > 0.0) requirement.sigma_f0_hz = a.sigma_f0_hz;
  const analysis::ExcitationDesign d =
      analysis::DesignExcitationForTime(recipe.excitation, requirement);
  // What the recipe's own excitation reaches, for comparison.
  const analysis::ExcitationDrive own =
      analysis::DriveThrough(as_is.excitation, requirement.nominal);
  const json current = {
      {"sigma_f0_hz",
       analysis::PredictedSigmaF0Hz(as_is.excitation, as_is.AnalysedPeriods(), requirement)},
      {"record_s", static_cast<double>(as_is.periods + as_is.transient_periods) /
                       as_is.excitation.line_spacing_hz},
      {"peak_v", as_is.excitation.peak_v},
      {"current_peak_a", own.a_peak},
      {"line_spacing_hz", as_is.excitation.line_spacing_hz}};
  json out = {{"usable", d.usable},
              {"recipe_excitation", current},
              {"message", d.message},
              {"required_sigma_f0_hz", d.required_sigma_f0_hz},
              {"candidates", json::array()}};
  for (const auto& c : d.candidates) out["candidates"].push_back(CandidateJson(c));
  if (d.usable) out["chosen"] = CandidateJson(d.chosen);
  if (d.usable && !a.out.empty()) {
    if (std::filesystem::exists(a.out) && !a.force)
      throw std::runtime_error(a.out +
                               " exists: refusing to overwrite it (choose another --out, "
                               "or --force)");
    const json j = RecipeToJson(Designed(recipe, d, requirement, own));
    const Recipe checked = ParseRecipe(j, a.out);  // validated (and its bound re-checked) first
    WriteRecipeFile(a.out, j);
    out["written"] = {{"path", a.out}, {"version", checked.version}, {"hash", checked.hash}};
  }
  if (a.json) {
    std::cout << out.dump(2) << std::endl;
    return d.usable ? 0 : 1;
  }
  std::printf("required std(f0) %.5f Hz at the nominal motor (f0 %.1f Hz, Q %.1f)\n",
              d.required_sigma_f0_hz, requirement.nominal.f0_hz, requirement.nominal.q);
  std::printf(
      "the recipe's own excitation: std(f0) %.5f Hz in %.3f s (%.4f Hz lines, %.3f V peak, "
      "%.3f A peak)\n",
      current["sigma_f0_hz"].get<double>(), current["record_s"].get<double>(),
      as_is.excitation.line_spacing_hz, as_is.excitation.peak_v, own.a_peak);
  std::printf("%10s %6s %8s %-19s %7s %7s %8s %8s %9s %10s\n", "lines Hz", "lines", "peak V",
              "limited by", "V rms", "A rms", "A peak", "periods", "record s", "std(f0) Hz");
  for (const auto& c : d.candidates)
    std::printf("%10.4f %6zu %8.3f %-19s %7.3f %7.3f %8.3f %8zu %9.3f %10.5f%s\n",
                c.line_spacing_hz, c.lines, c.peak_v, c.amplitude_limited_by.c_str(), c.v_rms,
                c.a_rms, c.current_peak_a, c.periods, c.record_s, c.sigma_f0_hz,
                c.meets ? "" : "  (too long)");
  if (!d.usable) {
    std::fprintf(stderr, "eol design-excitation: %s\n", d.message.c_str());
    return 1;
  }
  std::printf("chosen: %.4f Hz lines, %.3f V peak, %zu periods from rest = %.3f s per phase pair\n",
              d.chosen.line_spacing_hz, d.chosen.peak_v, d.chosen.periods, d.chosen.record_s);
  if (out.contains("written"))
    std::printf("wrote %s: v%d, a proposal until approved (eol recipe-approve), sha256 %s\n",
                a.out.c_str(), out["written"]["version"].get<int>(),
                out["written"]["hash"].get<std::string>().c_str());
  return 0;
}

}  // namespace

void AddDesignExcitationCommand(CLI::App& app) {
  auto args = std::make_shared<DesignArgs>();
  CLI::App* cmd = app.add_subcommand(
      "design-excitation",
      "Design the shortest multisine that meets the recipe's \"excitation_design\" requirement:\n"
      "std(f0) at the nominal motor (Cramer-Rao bound with the DAQ's noise), the amplitude as\n"
      "high as max_peak_v, max_v_rms / max_a_rms and 0.8 of the current full scale allow, the\n"
      "line grid just fine enough to resolve the mode (--crest-for current: the phases keep\n"
      "the current's crest factor low where the current range limits). Prints every\n"
      "candidate; --out writes the recipe with that excitation (played from rest,\n"
      "transient_lpm) as a proposal.\n"
      "Exit: 0 designed, 1 no excitation meets the requirement, 2 usage or file error.");
  cmd->add_option("--recipe", args->recipe, "Recipe with an excitation_design block")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--sigma-f0-hz", args->sigma_f0_hz,
                  "Required std(f0) in Hz (default: the recipe's)")
      ->check(Positive());
  cmd->add_option("--crest-for", args->crest_for,
                  "Phases that keep the voltage's or the current's crest factor low (default: "
                  "the recipe's excitation.crest_for)")
      ->check(CLI::IsMember({"voltage", "current"}));
  cmd->add_option("--out", args->out, "Write the designed recipe (version + 1) here");
  cmd->add_flag("--force", args->force, "Overwrite --out if it exists");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("design-excitation", [&] { return RunDesign(*args); }); });
}

}  // namespace eol::station::cli
