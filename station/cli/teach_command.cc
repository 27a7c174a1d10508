// `eol teach --recipe R --golden FILES... [--bad FILES...] [--known-bad-from-db DB] --out R2`:
// limits learned from good units, and placed against confirmed-defective ones when given
// (analysis/qc/teach.h). The new recipe is R with every declared scalar limit's bounds and
// marginal band replaced by the learned ones, its masks replaced by the learned Re Z mask
// (kept when no curve was given), version + 1 and a note in the description. It is validated
// (ParseRecipe) before it is written, and an existing file is never overwritten without
// --force. Golden units of another motor (station/daemon/qc_service.h ForeignGoldenUnits) are
// refused naming each quantity that disagrees and by how much, unless --force-foreign (then
// recorded in the taught recipe). The winding-temperature reference is relearned from the golden
// units (RelearnWindingReference), with a warning when the old one read them as implausible. Exit:
// 0 written, 1 nothing could be learned or the golden units are another motor's (reason on stderr),
// 2 usage/file error.
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/golden_inputs.h"
#include "station/cli/progress.h"
#include "station/daemon/qc_service.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct TeachArgs {
  std::string recipe;
  std::vector<std::string> golden;
  std::vector<std::string> bad;
  std::string bad_db;  // --known-bad-from-db
  std::string out;
  analysis::TeachOptions options;
  bool force = false;
  bool force_foreign = false;
  bool json = false;
};

void WriteNew(const std::string& path, const json& j, bool force) {
  if (std::filesystem::exists(path) && !force)
    throw std::runtime_error(path +
                             " exists: refusing to overwrite it (choose another --out, or "
                             "--force)");
  WriteRecipeFile(path, j);
}

int RunTeach(const TeachArgs& a) {
  std::string why;
  if (!a.options.IsValid(&why)) throw std::runtime_error("options: " + why);
  const Recipe recipe = LoadRecipe(a.recipe);
  analysis::TeachOptions options = a.options;  // the bond index for the recipe's motor
  if (recipe.bond_index) options.bond_residue_to_f0 = recipe.bond_index->residue_to_f0;
  if (std::filesystem::exists(a.out) && !a.force)
    throw std::runtime_error(a.out +
                             " exists: refusing to overwrite it (choose another --out, or "
                             "--force)");
  std::vector<std::string> skipped;
  auto progress = std::make_unique<Progress>("teach");
  const std::vector<analysis::GoldenUnit> golden =
      ReadGoldenUnits(a.golden, recipe, &skipped, false, progress->Callback());
  std::vector<analysis::GoldenUnit> bad =
      a.bad.empty()
          ? std::vector<analysis::GoldenUnit>{}
          : ReadGoldenUnits(a.bad, recipe, nullptr, /*known_bad=*/true, progress->Callback());
  std::vector<std::string> bad_skipped;
  if (!a.bad_db.empty())
    for (analysis::GoldenUnit& u : ReadKnownBadFromStore(a.bad_db, recipe, &bad_skipped))
      bad.push_back(std::move(u));
  progress.reset();  // ends the line before the results
  const std::vector<std::string> foreign = ForeignGoldenUnits(recipe, golden);
  if (!foreign.empty()) {
    const std::string why = ForeignGoldenRefusal(recipe, foreign, "--force-foreign");
    if (!a.force_foreign) {
      std::cerr << "eol teach: refused: " << why << std::endl;
      if (a.json)
        std::cout << json{{"usable", false}, {"error", why}, {"foreign", foreign}}.dump()
                  << std::endl;
      return 1;
    }
    std::cerr << "eol teach: warning: forced (--force-foreign): " << why << "\n";
  }
  const analysis::TeachSummary s = analysis::TeachLimits(recipe.limits, golden, options, bad);
  for (const std::string& k : skipped) std::cerr << "eol teach: skipped " << k << "\n";
  for (const std::string& k : bad_skipped)
    std::cerr << "eol teach: known-bad unit left out: " << k << "\n";
  if (!s.usable) {
    std::cerr << "eol teach: nothing learned: " << s.message << std::endl;
    if (a.json) std::cout << json{{"usable", false}, {"error", s.message}}.dump() << std::endl;
    return 1;
  }
  const json taught = TaughtRecipeJson(recipe, s, a.options, foreign);
  // Validated before anything is written; only an excitation short of its requirement at the
  // relearned nominal is written (to be redesigned), never loaded: see ExcitationShortOfDesign.
  const Recipe next = ParseRecipe(taught, a.out, {.check_excitation_design = false});
  const std::string short_of_design = ExcitationShortOfDesign(taught, a.out);
  WriteNew(a.out, taught, a.force);
  if (!short_of_design.empty()) std::cerr << "eol teach: warning: " << short_of_design << "\n";
  const WindingReference winding = RelearnWindingReference(recipe, s);
  if (!winding.warning.empty()) std::cerr << "eol teach: warning: " << winding.warning << "\n";

  if (a.json) {
    json out = TeachSummaryJson(s, a.options);
    out["recipe"] = {
        {"path", a.out}, {"id", next.id}, {"version", next.version}, {"hash", next.hash}};
    out["previous"] = {{"path", a.recipe}, {"version", recipe.version}, {"hash", recipe.hash}};
    out["skipped"] = skipped;
    out["known_bad_skipped"] = bad_skipped;
    out["foreign_forced"] = foreign;
    out["excitation_short_of_design"] = short_of_design;
    out["winding_reference"] = {
        {"relearned", winding.relearned}, {"old_r_ref_ohm", winding.old_r_ref_ohm},
        {"r_ref_ohm", winding.r_ref_ohm}, {"t_ref_c", winding.t_ref_c},
        {"note", winding.note},           {"warning", winding.warning}};
    if (s.known_bad_units > 0)
      out["known_bad"] = {
          {"units", s.known_bad_units},     {"escapes_budget", s.known_bad_escapes_budget},
          {"escapes", s.known_bad_escapes}, {"f0_lo_budget_hz", s.f0_lo_budget_hz},
          {"f0_lo_hz", s.f0_lo_hz},         {"moved_share", s.known_bad_moved_share},
          {"donors", s.known_bad_donors}};
    std::cout << out.dump() << std::endl;
    return 0;
  }
  std::cout << "teach: " << s.message << "\n";
  for (const std::string& r : s.rejected) std::cout << "  rejected golden unit " << r << "\n";
  std::cout << "clamp-pressure-normalised resonance: " << s.f0_pressure.note << "\n";
  std::cout << winding.note << "\n";
  for (std::size_t i = 0; i < s.limits.size(); ++i) {
    // By name: teach declares or drops resonance_f_ref_pressure_hz itself.
    analysis::Limit old;
    for (const analysis::MeasurementSpec& l : recipe.limits)
      if (l.name == s.limits[i].name) old = l.limit;
    const auto& now = s.limits[i].limit;
    auto bound = [](const std::optional<double>& v) {
      return v ? json(*v).dump() : std::string("-");
    };
    // Centre and scale on the scale it was taught on (" (taught on ln(1 + x))", teach.h).
    const std::string& stat = s.statistics[i].name;
    const std::string scale_taught =
        stat.size() > s.limits[i].name.size() ? stat.substr(s.limits[i].name.size()) : "";
    std::cout << "  " << s.limits[i].name << ": [" << bound(old.lo) << ", " << bound(old.hi)
              << "] -> [" << bound(now.lo) << ", " << bound(now.hi) << "], marginal "
              << now.marginal << " (centre " << s.statistics[i].centre << ", scale "
              << s.statistics[i].scale << scale_taught << ")\n";
  }
  std::cout << "expected false rejects " << 100.0 * s.expected_false_reject << " % ("
            << 100.0 * a.options.confidence << " % interval " << 100.0 * s.false_reject_lo << "-"
            << 100.0 * s.false_reject_hi << " %), target " << 100.0 * (1.0 - a.options.coverage)
            << " %\n";
  for (const auto& m : s.masks)
    std::cout << "  mask " << m.name << ": " << m.points.size() / 2 << " segments "
              << m.points.front().f_hz << "-" << m.points.back().f_hz << " Hz on Re Z, guard "
              << m.guard_sigma << " sigma\n";
  if (s.known_bad_units > 0) {
    std::cout << "known-bad units: " << s.known_bad_units << "; pass the limits the budget alone "
              << "sets: " << s.known_bad_escapes_budget.size() << "; f0 lower bound "
              << s.f0_lo_budget_hz << " -> " << s.f0_lo_hz << " Hz (share "
              << s.known_bad_moved_share
              << " moved); pass the taught limits: " << s.known_bad_escapes.size() << "\n";
    for (const std::string& e : s.known_bad_escapes)
      std::cout << "  known-bad unit passes: " << e << "\n";
  }
  std::cout << "units needed for the stated confidence: " << s.units_needed << " ("
            << s.units_needed_distribution_free << " distribution-free); used " << s.units_used
            << "\n";
  std::cout << "wrote " << a.out << ": " << next.id << " v" << next.version << " (was v"
            << recipe.version << "), sha256 " << next.hash << "\n";
  return 0;
}

}  // namespace

void AddTeachCommand(CLI::App& app) {
  auto args = std::make_shared<TeachArgs>();
  CLI::App* cmd = app.add_subcommand(
      "teach",
      "Learn a recipe's limits from good units: one-sided tolerance bounds (or median/MAD) for\n"
      "every declared measurement and a Re Z mask over frequency, at a stated false-reject\n"
      "target (default 0.3 %) and confidence, the budget spent where defects move each\n"
      "measurement; reports the expected false-reject rate with its interval. Refuses FAIL,\n"
      "ERROR and ABORTED records, masters, records of another recipe, and fewer units than\n"
      "needed (unless --allow-few-units). Writes a new recipe version (never overwrites without "
      "--force) and\n"
      "prints its SHA-256 and how many golden units the stated confidence needs.\n"
      "Golden files: FRF CSV / .zma / recording CSV (analysed with the recipe), `eol analyze\n"
      "--json` output, or `eol export --format records` records.\n"
      "Exit: 0 written, 1 nothing could be learned, 2 usage or file error.");
  cmd->add_option("--recipe", args->recipe, "Recipe whose limits are taught")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--golden", args->golden, "Files of good units")->required()->expected(1, -1);
  cmd->add_option("--bad", args->bad,
                  "Files of units confirmed defective (limit masters, torn-down rejects; PASS or "
                  "FAIL): the f0 lower bound takes budget from bounds that catch none of them "
                  "until it catches those it can; teach reports the escapes before and after")
      ->expected(1, -1);
  cmd->add_option("--known-bad-from-db", args->bad_db,
                  "Also take as known-bad units every serial this store's teardown findings\n"
                  "confirm defective (`eol teardown`), as measured by the test each finding\n"
                  "judged; units of another recipe or without a PASS/FAIL test are left out\n"
                  "and named")
      ->check(CLI::ExistingFile);
  cmd->add_option("--bad-max-donation", args->options.known_bad_max_donation,
                  "With --bad: share of each other bound's budget (above plausibility) that may "
                  "move to the f0 lower bound")
      ->capture_default_str();
  cmd->add_option("--out", args->out, "The new recipe file")->required();
  cmd->add_option("--confidence", args->options.confidence, "Confidence of the tolerance intervals")
      ->capture_default_str();
  cmd->add_option("--coverage", args->options.coverage,
                  "Share of good units that pass every taught bound together (1 - the "
                  "false-reject target)")
      ->capture_default_str();
  std::vector<std::string> methods;  // the names of analysis/qc/teach.h
  for (analysis::TeachMethod m : analysis::kAllTeachMethods)
    methods.push_back(analysis::ToString(m));
  cmd->add_option_function<std::string>(
         "--method",
         [args](const std::string& name) {
           args->options.method = analysis::ParseTeachMethod(name);
         },
         "tolerance_interval (default) or mad")
      ->check(CLI::IsMember(methods));
  cmd->add_option_function<double>(
         "--false-reject", [args](double share) { args->options.coverage = 1.0 - share; },
         "Target share of good units rejected (default 0.003; sets --coverage to 1 - it)")
      ->excludes("--coverage");
  cmd->add_option("--allocation", args->options.allocation,
                  "How the false-reject budget is shared: physics (by the side a defect moves "
                  "each measurement) or even (the same for every bound)")
      ->capture_default_str()
      ->check(CLI::IsMember({"physics", "even"}));
  cmd->add_flag("--allow-few-units", args->options.allow_few_units,
                "Teach from fewer golden units than the method needs (the recipe says so)");
  cmd->add_option("--mask-segments", args->options.mask_segments,
                  "Segments of the taught Re Z mask (0: keep the recipe's masks)")
      ->capture_default_str();
  cmd->add_option("--outlier-z", args->options.outlier_z,
                  "Robust z beyond which a golden unit is left out")
      ->capture_default_str();
  cmd->add_flag("--force", args->force, "Overwrite --out if it exists");
  cmd->add_flag("--force-foreign", args->force_foreign,
                "Teach from golden units that do not look like the recipe's motor (f0 more\n"
                "than 15 % from the recipe's, R, L or residue beyond a factor 1.5); the taught\n"
                "recipe's description and approval note record it");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("teach", [&] { return RunTeach(*args); }); });
}

}  // namespace eol::station::cli
