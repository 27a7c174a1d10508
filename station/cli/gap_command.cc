// `eol gap`: the sim-to-real gap diagnosis (analysis/gap/diagnosis.h) from files: where the
// measurement leaves the simulation, which unmodelled effect explains it, how far the gap
// shrinks (also on held-out lines or units), and optionally where a second simulated design
// would land in the measured set-up (--predict-sim). Inputs: drivers/io/gap_inputs.h;
// report: gap_report.h; plot: drivers/io/chart.h.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <iostream>
#include <numbers>
#include <sstream>

#include "analysis/gap/noise.h"
#include "drivers/io/chart.h"
#include "drivers/io/file_error.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/gap_report.h"
#include "station/data_files.h"
#include "station/recipe.h"

namespace eol::station::cli {
namespace {

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
  double period_s = 0.0;
  std::string input_column, output_column, lines_file;
  std::vector<std::string> effects;
  bool no_pairs = false;
};

// Keeps the lines in [lo, hi] (0: no limit).
void Band(analysis::Frf* f, double lo, double hi) {
  analysis::Frf out;
  out.quantity = f->quantity;
  out.method = f->method;
  for (std::size_t k = 0; k < f->size(); ++k) {
    if ((lo > 0.0 && f->freq_hz[k] < lo) || (hi > 0.0 && f->freq_hz[k] > hi)) continue;
    out.freq_hz.push_back(f->freq_hz[k]);
    out.value.push_back(f->value[k]);
    if (f->has_sigma()) out.sigma.push_back(f->sigma[k]);
  }
  *f = std::move(out);
}

double RecipeInertia(const std::string& path) {
  try {
    return LoadRecipe(path).rotor_inertia_kg_m2;
  } catch (const std::exception&) {
    return 0.0;  // no recipe: J_r stays unknown and the fixture is reported as a ratio
  }
}

analysis::CalibrationSummary Calibrate(const io::GapInput& sim, double inertia) {
  if (sim.model) {
    analysis::CalibrationSummary c;
    c.usable = true;
    c.nominal = *sim.model;
    if (c.nominal.inertia_kg_m2 <= 0.0) c.nominal.inertia_kg_m2 = inertia;
    c.message = "nominal given exactly by the model";
    c.params = {{"gain_rad_per_s2_per_a", "rad/s^2/A", c.nominal.rigid.gain_rad_per_s2_per_a, 0.0},
                {"damping_per_s", "1/s", c.nominal.rigid.damping_per_s, 0.0}};
    return c;
  }
  analysis::CalibrationOptions o;
  o.inertia_kg_m2 = inertia;
  return analysis::CalibrateNominal(sim.frf, o);
}

io::Chart Plot(const GapReport& r, const io::GapInput& meas) {
  const bool mobility = r.quantity == analysis::Quantity::kMobility;
  const analysis::NominalNetwork& n = r.calibration.nominal;
  const auto& f = meas.frf.freq_hz;
  io::Chart fig;
  fig.panel_height_px = 260;
  fig.title = "eol gap: " + r.gap.effect + "  (g " + std::to_string(r.gap.gap_before).substr(0, 6) +
              " -> " + std::to_string(r.gap.gap_after).substr(0, 6) + ")  " + meas.source;
  const bool log_x = f.back() / f.front() > 10.0;
  std::vector<io::ChartBand> shaded;
  for (const auto& b : r.gap.where) {
    io::ChartBand band;
    band.label = shaded.empty() ? "where the gap is" : "";
    band.lo = b.band.f_lo_hz;
    band.hi = b.band.f_hi_hz;
    band.colour = {0.957, 0.635, 0.380};
    band.alpha = 0.25;
    shaded.push_back(band);
  }
  auto series = [&](const std::string& label, io::Colour colour, const std::vector<double>& y,
                    bool markers, double width, bool dashed) {
    io::ChartSeries c;
    c.label = label;
    c.colour = colour;
    c.x = f;
    c.y = y;
    c.line = !markers;
    c.markers = markers;
    c.marker_radius = 1.6;
    c.width = width;
    c.style = dashed ? io::LineStyle::kDashed : io::LineStyle::kSolid;
    return c;
  };
  auto base = [&](const std::string& y_label, bool log_y) {
    io::ChartPanel p;
    p.x_label = "frequency (Hz)";
    p.y_label = y_label;
    p.log_x = log_x;
    p.log_y = log_y;
    p.vbands = shaded;
    return p;
  };
  // Curves: measured, simulated (the calibrated nominal), corrected (nominal + winner).
  std::vector<double> m1, m2, s1, s2, c1, c2, before, after;
  for (std::size_t k = 0; k < f.size(); ++k) {
    const std::complex<double> hm = meas.frf.value[k];
    const std::complex<double> hs = n.At(f[k]);
    const std::complex<double> hc = analysis::EvaluateNetwork(n, r.gap.winner, f[k]);
    if (mobility) {
      m1.push_back(std::abs(hm));
      s1.push_back(std::abs(hs));
      c1.push_back(std::abs(hc));
      m2.push_back(std::arg(hm) * 180.0 / std::numbers::pi);
      s2.push_back(std::arg(hs) * 180.0 / std::numbers::pi);
      c2.push_back(std::arg(hc) * 180.0 / std::numbers::pi);
    } else {
      // Im Z minus the nominal's w L shows the motional part under the inductive background.
      const double wl = 2.0 * std::numbers::pi * f[k] * n.motional.l_h;
      m1.push_back(hm.real());
      s1.push_back(hs.real());
      c1.push_back(hc.real());
      m2.push_back(hm.imag() - wl);
      s2.push_back(hs.imag() - wl);
      c2.push_back(hc.imag() - wl);
    }
    before.push_back(std::abs(hm - hs) / meas.frf.sigma[k]);
    after.push_back(std::abs(hm - hc) / meas.frf.sigma[k]);
  }
  auto panel = [&](const std::string& label, const std::vector<double>& m,
                   const std::vector<double>& s, const std::vector<double>& c, bool log_y) {
    io::ChartPanel p = base(label, log_y);
    p.series.push_back(series("measured", {0.267, 0.267, 0.267}, m, true, 1.0, false));
    p.series.push_back(series("simulated", io::kChartBlue, s, false, 1.6, true));
    p.series.push_back(series("corrected", io::kChartRed, c, false, 1.6, false));
    return p;
  };
  if (mobility) {
    fig.panels.push_back(panel("|H| (rad/s/A)", m1, s1, c1, true));
    fig.panels.push_back(panel("phase H (deg)", m2, s2, c2, false));
  } else {
    fig.panels.push_back(panel("Re Z (ohm)", m1, s1, c1, false));
    fig.panels.push_back(panel("Im Z - w L_nominal (ohm)", m2, s2, c2, false));
  }
  io::ChartPanel res = base("|residual| / sigma", true);
  io::ChartLine one;
  one.label = "1 sigma";
  one.value = 1.0;
  one.colour = io::kChartGrey;
  one.style = io::LineStyle::kDotted;
  res.hlines.push_back(one);
  res.series.push_back(series("simulated", io::kChartBlue, before, false, 1.0, false));
  res.series.push_back(series("corrected", io::kChartRed, after, false, 1.0, false));
  fig.panels.push_back(res);
  return fig;
}

int RunGap(const GapArgs& a) {
  io::GapInputOptions io;
  io.quantity =
      a.quantity == "mobility" ? analysis::Quantity::kMobility : analysis::Quantity::kImpedanceOhm;
  io.period_s = a.period_s;
  io.input_column = a.input_column;
  io.output_column = a.output_column;
  io.lines_file = a.lines_file;

  GapReport r;
  r.quantity = io.quantity;
  r.sigma_pool = a.sigma_pool;
  // P periods give sigma^2 with 2 (P - 1) degrees of freedom per line; pooling over 2 N + 1
  // lines multiplies them.
  const double dof = a.sigma_dof > 0.0 ? a.sigma_dof : 2.0 * std::max(a.sigma_periods - 1, 0);
  r.sigma_dof = dof * (2 * a.sigma_pool + 1);
  for (const std::string& path : a.measured) {
    io::GapInput m = io::ReadGapMeasurement(path, io);
    Band(&m.frf, a.f_lo_hz, a.f_hi_hz);
    if (m.frf.size() < 10) throw io::FileError(path, 0, 0, "fewer than 10 lines in the band");
    r.measured.push_back(std::move(m));
  }
  const std::vector<double>& lines = r.measured.front().frf.freq_hz;
  r.simulation = io::ReadGapSimulation(a.sim, io, lines);
  Band(&r.simulation.frf, a.f_lo_hz, a.f_hi_hz);
  double inertia = a.inertia_kg_m2 > 0.0                              ? a.inertia_kg_m2
                   : r.simulation.inertia_kg_m2 > 0.0                 ? r.simulation.inertia_kg_m2
                   : io.quantity == analysis::Quantity::kImpedanceOhm ? RecipeInertia(a.recipe)
                                                                      : 0.0;
  r.calibration = Calibrate(r.simulation, inertia);
  if (!r.calibration.usable) {
    std::cerr << "eol gap: " << a.sim << ": " << r.calibration.message << "\n";
    return 2;
  }

  std::vector<analysis::GapUnit> units;
  for (const io::GapInput& m : r.measured) {
    analysis::GapUnit u;
    u.name = m.source;
    u.freq_hz = m.frf.freq_hz;
    u.value = m.frf.value;
    u.sigma = m.sigma_estimated ? m.frf.sigma : analysis::PoolLineSigma(m.frf, a.sigma_pool);
    u.sigma_dof = m.sigma_estimated ? 0.0 : r.sigma_dof;
    units.push_back(std::move(u));
  }
  analysis::GapOptions go;
  go.try_pairs = !a.no_pairs;
  for (const std::string& name : a.effects) {
    const auto kind = analysis::ParseEffectKind(name);
    if (!kind) throw std::invalid_argument("--effects: unknown effect '" + name + "'");
    go.effects.push_back(*kind);
  }
  r.gap = analysis::DiagnoseGap(r.calibration.nominal, units, go);
  if (!r.gap.usable) {
    std::cerr << "eol gap: " << r.gap.message << "\n";
    return 2;
  }
  analysis::CalibrationOptions co;
  for (const analysis::GapUnit& u : units)
    r.features.push_back(analysis::CompareFeatures(r.calibration, u, io.quantity, co));

  if (!a.predict_sim.empty()) {
    GapPrediction p;
    p.simulation = io::ReadGapSimulation(a.predict_sim, io, lines);
    Band(&p.simulation.frf, a.f_lo_hz, a.f_hi_hz);
    const double j2 = p.simulation.inertia_kg_m2 > 0.0 ? p.simulation.inertia_kg_m2 : inertia;
    p.calibration = Calibrate(p.simulation, j2);
    if (!p.calibration.usable) {
      std::cerr << "eol gap: " << a.predict_sim << ": " << p.calibration.message << "\n";
      return 2;
    }
    analysis::RankedEffect none;
    const analysis::RankedEffect* w = Winner(r.gap);
    p.prediction = analysis::PredictWithEffects(r.calibration.nominal, w ? *w : none,
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
    io::WriteChart(a.plot, Plot(r, r.measured.front()));
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
      "(fixture compliance, lossy inductance, stray capacitance, channel delay, second mode,\n"
      "series resistance, skin effect, adhesive creep, or a pair) explains it, and how far the\n"
      "gap shrinks, also on held-out lines (one unit) or units (leave-one-unit-out).");
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
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--recipe", a->recipe, "Recipe giving the default J_r")->capture_default_str();
  cmd->add_option("--f-lo-hz", a->f_lo_hz, "Use only lines at or above this frequency")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--f-hi-hz", a->f_hi_hz, "Use only lines at or below this frequency")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--sigma-pool", a->sigma_pool,
                  "Pool each line's relative variance over +-N lines, for files whose sigma rests "
                  "on few periods and was not pooled (the periodic estimator already pools: 0)")
      ->capture_default_str()
      ->check(CLI::Range(0, 50));
  cmd->add_option("--sigma-periods", a->sigma_periods,
                  "The measured files' sigma comes from this many periods: each sigma^2 has "
                  "2 (P - 1) degrees of freedom and the residual is tested as F, not chi2 "
                  "(default: sigma exact)")
      ->check(CLI::Range(4, 100000));
  cmd->add_option("--sigma-dof", a->sigma_dof,
                  "Degrees of freedom of each line's sigma^2 in the measured files (above 4; "
                  "overrides --sigma-periods)")
      ->check(CLI::Range(4.000001, 1e12));
  cmd->add_option("--period-s", a->period_s,
                  "Raw recordings: the excitation period (default: detect)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--input-column", a->input_column,
                  "Raw recordings: input column (default i_a, mobility iq_a)");
  cmd->add_option("--output-column", a->output_column,
                  "Raw recordings: output column (default u_v, mobility theta_motor_rad)");
  cmd->add_option("--lines-file", a->lines_file,
                  "Raw recordings: excited lines in Hz, one per line (default: "
                  "<stem>-excited-lines-hz.txt beside the recording, else detected)");
  cmd->add_option("--effects", a->effects, "Only try these effects (names as in the report)")
      ->delimiter(',');
  cmd->add_flag("--no-pairs", a->no_pairs, "Do not try pairs of effects");
  cmd->callback([a] { RunGuarded("gap", [&] { return RunGap(*a); }); });
}

}  // namespace eol::station::cli
