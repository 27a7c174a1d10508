// `eol recipe-new --motor MOTOR.json --out RECIPE.json [--golden FILES...]`: a recipe proposed
// from a motor's design data (station/daemon/recipe_design.h: band, windows, excitation designed
// for time from a stated requirement, conditions' references, design limits, no masks, the bond
// index's direction from the motor's chain). With --golden the design is first calibrated to
// the measured good units (files as `eol teach` reads them, analysed with the design's
// recipe), saying where design and units disagree and by how much. Writes a proposal (never
// over an existing file without --force); then `eol teach`, `eol recipe-approve`.
// Exit: 0 written, 2 usage, file or design error (the reason on stderr).
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "drivers/io/motor_json.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/golden_inputs.h"
#include "station/daemon/recipe_design.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct RecipeNewArgs {
  std::string motor;
  std::string out;
  std::string id;  // empty: the motor's id
  std::vector<std::string> golden;
  RecipeNewOptions options;
  bool force = false;
  bool json = false;
};

// The design calibrated to the golden units, read with the design's own recipe.
Calibration Calibrate(const RecipeNewArgs& a, const RecipeBasis& design, const std::string& id) {
  const RecipeProposal first = ProposeRecipe(design, a.options, id);
  const Recipe recipe = ParseRecipe(first.recipe, "the design's recipe");
  std::vector<std::string> skipped;
  return CalibrateToGolden(design, ReadGoldenUnits(a.golden, recipe, &skipped));
}

int RunRecipeNew(const RecipeNewArgs& a) {
  if (std::filesystem::exists(a.out) && !a.force)
    throw std::runtime_error(a.out +
                             " exists: refusing to overwrite it (choose another --out, or "
                             "--force)");
  const io::MotorSpec motor = io::LoadMotorJson(a.motor);
  const std::string id = a.id.empty() ? motor.id : a.id;
  RecipeBasis basis = BasisFromMotor(motor);
  Calibration calibration;
  if (!a.golden.empty()) {
    calibration = Calibrate(a, basis, id);
    basis = calibration.basis;
  }
  const RecipeProposal p = ProposeRecipe(basis, a.options, id);
  WriteRecipeFile(a.out, p.recipe);
  const Recipe written = ParseRecipe(p.recipe, a.out);
  if (a.json) {
    std::cout << json{{"recipe", {{"path", a.out}, {"id", written.id}, {"hash", written.hash}}},
                      {"motor", motor.id},
                      {"required_sigma_f0_hz", p.required_sigma_f0_hz},
                      {"residue_to_f0", basis.residue_to_f0},
                      {"notes", p.notes},
                      {"golden_units", calibration.units},
                      {"disagreements", calibration.disagreements}}
                     .dump()
              << std::endl;
    return 0;
  }
  std::cout << "recipe-new: motor " << motor.id << " (" << basis.source << ")\n";
  for (const std::string& n : p.notes) std::cout << "  " << n << "\n";
  if (calibration.units > 0)
    std::cout << "design against " << calibration.units << " golden units:\n";
  for (const std::string& d : calibration.disagreements) std::cout << "  " << d << "\n";
  std::cout << "wrote " << a.out << ": " << written.id << " v" << written.version
            << ", a proposal: teach it (eol teach --recipe " << a.out
            << " --golden ...), then eol recipe-approve; sha256 " << written.hash << "\n";
  return 0;
}

}  // namespace

void AddRecipeNewCommand(CLI::App& app) {
  auto args = std::make_shared<RecipeNewArgs>();
  CLI::App* cmd = app.add_subcommand(
      "recipe-new",
      "Propose a recipe for a motor type from its motor JSON (recipes/motors/): the band an\n"
      "octave either side of the chain's mode, the f0 window, the excitation designed for\n"
      "time (std(f0) = --shift-fraction x the f0 shift of a half-soft rotor), the winding\n"
      "reference, design limits (no masks until taught) and the bond index's defect direction\n"
      "from the motor's own chain. --golden calibrates the design to measured good units and\n"
      "says where they disagree. Writes a proposal; then eol teach and eol recipe-approve.\n"
      "Exit: 0 written, 2 usage, file or design error.");
  cmd->add_option("--motor", args->motor, "Motor JSON (format: drivers/io/motor_json.h)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "The proposed recipe file")->required();
  cmd->add_option("--id", args->id, "Recipe id (default: the motor's id)");
  cmd->add_option("--golden", args->golden,
                  "Files of good units (as eol teach reads them): calibrate the design to them")
      ->expected(1, -1);
  RecipeNewOptions& o = args->options;
  cmd->add_option("--sample-rate-hz", o.sample_rate_hz, "The DAQ's sample rate")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--noise-v", o.noise_v_rms, "The DAQ's voltage noise, V rms per sample")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--noise-a", o.noise_a_rms, "The DAQ's current noise, A rms per sample")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--max-peak-v", o.max_peak_v, "The amplifier's largest peak voltage")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--current-full-scale-a", o.current_full_scale_a,
                  "The current channel's full scale (the peak current stays within 0.8 of it)")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_option("--t-ref-c", o.t_ref_c, "Temperature of the motor file's winding r_ohm")
      ->capture_default_str();
  cmd->add_option("--shift-fraction", o.shift_fraction,
                  "Required std(f0) as a share of the half-soft rotor's f0 shift")
      ->capture_default_str()
      ->check(Positive());
  cmd->add_flag("--force", args->force, "Overwrite --out if it exists");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("recipe-new", [&] { return RunRecipeNew(*args); }); });
}

}  // namespace eol::station::cli
