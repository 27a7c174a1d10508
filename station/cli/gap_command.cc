// `eol gap`: the sim-to-real gap diagnosis (analysis/gap/diagnosis.h) from files: where the
// measurement leaves the simulation, which unmodelled effect explains it, how far the gap
// shrinks (also on held-out lines or units), and optionally where a second simulated design
// would land in the measured set-up (--predict-sim). Inputs: drivers/io/gap_inputs.h;
// reading, diagnosis and plot: station/reports/gap_diagnosis.h (shared with POST /api/gap.svg);
// report: station/reports/gap_report.h.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <sstream>

#include "analysis/model/effects.h"
#include "drivers/io/chart.h"
#include "drivers/io/file_error.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/data_files.h"
#include "station/daemon/recipe.h"
#include "station/reports/gap_diagnosis.h"
#include "station/reports/gap_report.h"

namespace eol::station::cli {
namespace {

// The effect catalogue's names for a quantity (analysis/model/effects.h EffectsFor), joined
// with ", ": what --effects takes and the report names.
std::string EffectNames(analysis::Quantity quantity) {
  std::string names;
  for (const analysis::EffectKind kind : analysis::EffectsFor(quantity))
    names += (names.empty() ? "" : ", ") + std::string(analysis::ToString(kind));
  return names;
}

struct GapArgs {
  std::string sim;
  std::vector<std::string> measured;
  bool json = false;     // the JSON report on stdout (the text report then on stderr)
  std::string json_out;  // and/or into this file
  std::string plot;
  std::string quantity = "impedance";
  std::string predict_sim;
  double inertia_kg_m2 = 0.0;
  std::string recipe = DefaultRecipePath();
  double f_lo_hz = 0.0;
  double f_hi_hz = 0.0;
  int sigma_pool = 0;
  double sigma_dof = 0.0;
  int sigma_periods = 0;
  bool sigma_exact = false;
  double period_s = 0.0;
  std::string input_column, output_column, lines_file;
  std::vector<std::string> effects;
  bool no_pairs = false;
  std::string tolerances;
  bool fixed_nominal = false;
};

double RecipeInertia(const std::string& path) {
  try {
    return LoadRecipe(path).rotor_inertia_kg_m2;
  } catch (const std::exception&) {
    return 0.0;  // no recipe: J_r stays unknown and the fixture is reported as a ratio
  }
}

int RunGap(const GapArgs& a) {
  GapRunOptions o;
  o.io.quantity =
      a.quantity == "mobility" ? analysis::Quantity::kMobility : analysis::Quantity::kImpedanceOhm;
  o.io.period_s = a.period_s;
  o.io.input_column = a.input_column;
  o.io.output_column = a.output_column;
  o.io.lines_file = a.lines_file;
  o.f_lo_hz = a.f_lo_hz;
  o.f_hi_hz = a.f_hi_hz;
  o.sigma_pool = a.sigma_pool;
  // P periods give sigma^2 with 2 (P - 1) degrees of freedom per line; pooling over 2 N + 1
  // lines multiplies them.
  const double dof = a.sigma_dof > 0.0 ? a.sigma_dof : 2.0 * std::max(a.sigma_periods - 1, 0);
  o.sigma_dof = dof * (2 * a.sigma_pool + 1);
  o.sigma_exact = a.sigma_exact;
  o.inertia_kg_m2 = a.inertia_kg_m2;
  o.try_pairs = !a.no_pairs;
  o.tolerances = a.tolerances;
  o.calibrate = !a.fixed_nominal;
  for (const std::string& name : a.effects) {
    const auto kind = analysis::ParseEffectKind(name);
    if (!kind)
      throw std::invalid_argument("--effects: unknown effect '" + name + "'; the effects: " +
                                  EffectNames(analysis::Quantity::kImpedanceOhm));
    o.effects.push_back(*kind);
  }
  GapReport r;
  ReadGapInputs(a.sim, a.measured, o, &r);
  if (o.io.quantity == analysis::Quantity::kImpedanceOhm && o.inertia_kg_m2 <= 0.0 &&
      r.simulation.inertia_kg_m2 <= 0.0)
    o.fallback_inertia_kg_m2 = RecipeInertia(a.recipe);
  try {
    DiagnoseGapReport(o, &r);
  } catch (const GapNotUsable& e) {
    std::cerr << "eol gap: " << e.what() << "\n";
    return 2;
  }
  const io::GapInputOptions& io = o.io;
  const std::vector<double>& lines = r.measured.front().frf.freq_hz;
  const double inertia = r.inertia_kg_m2;

  if (!a.predict_sim.empty()) {
    GapPrediction p;
    p.simulation = io::ReadGapSimulation(a.predict_sim, io, lines);
    KeepBand(&p.simulation.frf, a.f_lo_hz, a.f_hi_hz);
    const double j2 = p.simulation.inertia_kg_m2 > 0.0 ? p.simulation.inertia_kg_m2 : inertia;
    p.calibration = CalibrateToSimulation(p.simulation, j2);
    if (!p.calibration.usable) {
      std::cerr << "eol gap: " << a.predict_sim << ": " << p.calibration.message << "\n";
      return 2;
    }
    analysis::RankedEffect none;
    const analysis::RankedEffect* w = Winner(r.gap);
    p.prediction = analysis::PredictWithEffects(r.gap.nominal_after, w ? *w : none,
                                                p.calibration.nominal, lines);
    r.prediction = std::move(p);
  }

  const nlohmann::json j = GapReportJson(r);
  std::ostream& text = a.json ? std::cerr : std::cout;
  text << GapReportText(r);
  if (a.json) std::cout << j.dump(2) << std::endl;
  if (!a.json_out.empty()) {
    std::ofstream out(a.json_out);
    out << j.dump(2) << "\n";
    if (!out) throw io::FileError(a.json_out, 0, 0, "cannot write the JSON report");
  }
  if (!a.plot.empty()) {
    io::WriteChart(a.plot, GapChart(r));
    text << "plot written to " << a.plot << "\n";
  }
  return 0;
}

}  // namespace

void AddGapCommand(CLI::App& app) {
  auto a = std::make_shared<GapArgs>();
  CLI::App* cmd = app.add_subcommand(
      "gap",
      "Sim-to-real gap diagnosis: calibrate the nominal model to a simulation, compare it with\n"
      "measured units, find where the residual is significant, which unmodelled effect\n"
      "explains it, and how far the gap shrinks, also on held-out lines (one unit) or units\n"
      "(leave-one-unit-out). The effects (or a pair of them):\n  " +
          EffectNames(analysis::Quantity::kImpedanceOhm) +
          "\nfor impedance; for mobility: " + EffectNames(analysis::Quantity::kMobility) + ".");
  cmd->add_option("--sim", a->sim,
                  "Simulation: FRF CSV (f_hz,re_ohm,im_ohm / f_hz,re,im), .zma, motor JSON "
                  "(recipes/motors) or rigid-shaft JSON")
      ->required();
  cmd->add_option("--measured", a->measured,
                  "Measured unit (repeatable): FRF CSV with sigma (else the noise is estimated), "
                  ".zma, or a raw periodic recording CSV with t_s (plain or .gz)")
      ->required();
  cmd->add_flag("--json", a->json, "Print the JSON report on stdout (the text goes to stderr)");
  cmd->add_option("--json-out", a->json_out, "Write the JSON report to this file");
  cmd->add_option("--plot", a->plot,
                  "Write an SVG plot: measured, simulated and corrected curves, the normalised "
                  "residual, gap bands shaded");
  cmd->add_option("--quantity", a->quantity, "impedance (Z = U/I) or mobility (j w Theta / I)")
      ->capture_default_str()
      ->check(CLI::IsMember({"impedance", "mobility"}));
  cmd->add_option("--predict-sim", a->predict_sim,
                  "A second simulation (same formats): predict where it rings in the measured "
                  "set-up, carrying the diagnosed effect over");
  cmd->add_option("--inertia-kg-m2", a->inertia_kg_m2,
                  "Rotor inertia J_r, to express the fixture's stiffness in N m/rad (default: "
                  "from the motor JSON, else the recipe's motor.rotor_inertia_kg_m2)")
      ->check(NonNegative());
  cmd->add_option("--recipe", a->recipe, "Recipe giving the default J_r")->capture_default_str();
  cmd->add_option("--f-lo-hz", a->f_lo_hz, "Use only lines at or above this frequency")
      ->check(NonNegative());
  cmd->add_option("--f-hi-hz", a->f_hi_hz, "Use only lines at or below this frequency")
      ->check(NonNegative());
  cmd->add_option("--sigma-pool", a->sigma_pool,
                  "Pool each line's relative variance over +-N lines, for files whose sigma rests "
                  "on few periods and was not pooled (the periodic estimator already pools: 0)")
      ->capture_default_str()
      ->check(Between(0, 50));
  cmd->add_option("--sigma-periods", a->sigma_periods,
                  "The measured files' sigma comes from this many periods: each sigma^2 has "
                  "2 (P - 1) degrees of freedom and the residual is tested as F, not chi2 "
                  "(default: the file's sigma_dof column, a raw recording's periodic estimate, "
                  "else read from the line-to-line scatter of sigma itself)")
      ->check(Between(4, 100000));
  auto* dof = cmd->add_option("--sigma-dof", a->sigma_dof,
                              "Degrees of freedom of each line's sigma^2 in the measured files "
                              "(above 4; overrides --sigma-periods)")
                  ->check(Between(4.000001, 1e12));
  cmd->add_flag("--sigma-exact", a->sigma_exact,
                "The measured files' sigma is exact (a noise model's): the residual is tested as "
                "chi2 whatever sigma's scatter")
      ->excludes(dof)
      ->excludes("--sigma-periods");
  cmd->add_option("--period-s", a->period_s,
                  "Raw recordings: the excitation period (default: detect)")
      ->check(NonNegative());
  cmd->add_option("--input-column", a->input_column,
                  "Raw recordings: input column (default i_a, mobility iq_a)");
  cmd->add_option("--output-column", a->output_column,
                  "Raw recordings: output column (default u_v, mobility theta_motor_rad)");
  cmd->add_option("--lines-file", a->lines_file,
                  "Raw recordings: excited lines in Hz, one per line (default: "
                  "<stem>-excited-lines-hz.txt beside the recording, else detected)");
  cmd->add_option("--effects", a->effects,
                  "Only try these effects, comma-separated (names as listed above and in the "
                  "report)")
      ->delimiter(',');
  cmd->add_flag("--no-pairs", a->no_pairs, "Do not try pairs of effects");
  auto* tol = cmd->add_option(
      "--tolerances", a->tolerances,
      "The design's tolerances the nominal is calibrated under in every fit, one sd each: "
      "name=value,... over the motor JSON's \"tolerances\", else the defaults r=0.1, l=0.08, "
      "torque_constant=0.06, inertia=0.06, stiffness=0.15, damping=3 (a factor), "
      "daq_gain=0.01");
  cmd->add_flag("--fixed-nominal", a->fixed_nominal,
                "Keep the nominal at the simulation's values in every fit (no calibration; the "
                "diagnosis before issue 38)")
      ->excludes(tol);
  cmd->callback([a] { RunGuarded("gap", [&] { return RunGap(*a); }); });
}

}  // namespace eol::station::cli
