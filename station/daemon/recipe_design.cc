#include "station/daemon/recipe_design.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "db/clock.h"

namespace eol::station {
namespace {

using analysis::Fixed;
using nlohmann::json;
namespace names = analysis::names;

double Down10(double f) { return 10.0 * std::floor(f / 10.0); }
double Up10(double f) { return 10.0 * std::ceil(f / 10.0); }

struct Band {
  double f_lo, f_hi, window_lo, window_hi;
};

Band BandFor(const RecipeBasis& b, const RecipeNewOptions& o) {
  const double f0 = b.nominal.f0_hz;
  Band band;
  band.window_lo = Down10(std::min(0.625 * f0, 0.9 * b.f0_all_soft_hz));
  band.window_hi = Up10(1.75 * f0);
  band.f_lo = Down10(std::min(0.5 * f0, 0.8 * band.window_lo));
  band.f_hi = Up10(2.0 * f0);
  if (band.f_hi > 0.45 * o.sample_rate_hz)
    throw std::invalid_argument(
        "the band up to " + Fixed(band.f_hi, 0) + " Hz (2 x the good rotor's mode at " +
        Fixed(f0, 1) + " Hz) needs a sample rate of at least " + Fixed(band.f_hi / 0.45, 0) +
        " Hz (--sample-rate-hz; given " + Fixed(o.sample_rate_hz, 0) + ")");
  return band;
}

json Limit(const char* name, std::optional<double> lo, std::optional<double> hi,
           const std::string& doc) {
  json l = {{"name", name}, {"doc", doc}};
  if (lo) l["lo"] = *lo;
  if (hi) l["hi"] = *hi;
  return l;
}

json DesignLimits(const analysis::MotionalImpedance& n) {
  const double a = n.ResidueOhmPerS();
  const std::string until =
      " First bounds from the design (eol recipe-new); eol teach sets them from golden units.";
  return json::array(
      {Limit("resonance_f_hz", 0.95 * n.f0_hz, 1.08 * n.f0_hz,
             "First torsional mode of the clamped rotor; a soft magnet bond lowers it." + until),
       Limit("resonance_q", n.q / 3.5, 3.0 * n.q,
             "Quality factor of the mode; a loose or lossy bond lowers it." + until),
       Limit("winding_r_ohm", 0.8 * n.r_ohm, 1.2 * n.r_ohm,
             "Phase-pair resistance at the test temperature." + until),
       Limit("winding_l_h", 0.8 * n.l_h, 1.2 * n.l_h, "Phase-pair inductance." + until),
       Limit("motional_residue_ohm_per_s", 0.6 * a, 1.55 * a,
             "T^2/J = Rp w0/Q: a soft bond raises it." + until),
       Limit("bond_index_pct", std::nullopt, 55.0,
             "Residue rise and resonance drop together (analysis/qc/bond_index.h), along the "
             "motor's own defect direction." +
                 until),
       Limit("second_mode_chi2_drop", std::nullopt, 60.0,
             "A soft magnet's own mode beside the rotor's." + until),
       Limit("fit_chi2_per_dof", std::nullopt, 3.0,
             "Goodness of fit: far above 1 means the curve is not the expected motor." + until)});
}

json ExcitationDesignBlock(const RecipeBasis& b, const RecipeNewOptions& o, double sigma) {
  const analysis::MotionalImpedance& n = b.nominal;
  return {
      {"sigma_f0_hz", sigma},
      {"noise_v_rms", o.noise_v_rms},
      {"noise_a_rms", o.noise_a_rms},
      {"max_peak_v", o.max_peak_v},
      {"current_full_scale_a", o.current_full_scale_a},
      {"lines_per_half_power_band", 1.85},
      {"min_periods", 2},
      {"nominal",
       {{"r_ohm", n.r_ohm}, {"l_h", n.l_h}, {"rp_ohm", n.rp_ohm}, {"f0_hz", n.f0_hz}, {"q", n.q}}}};
}

// The recipe before its excitation is designed (a placeholder grid, 1 V).
json Skeleton(const RecipeBasis& b, const RecipeNewOptions& o, const Band& band, double sigma,
              const std::string& id) {
  const analysis::MotionalImpedance& n = b.nominal;
  return {{"id", id},
          {"version", 1},
          {"description",
           "Proposed by eol recipe-new for motor " + b.motor_id + " from " + b.source + "."},
          {"motor", {{"poles", b.poles}, {"rotor_inertia_kg_m2", b.rotor_inertia_kg_m2}}},
          {"excitation",
           {{"f_lo_hz", band.f_lo},
            {"f_hi_hz", band.f_hi},
            {"line_spacing_hz", 10.0},
            {"sample_rate_hz", o.sample_rate_hz},
            {"peak_v", o.max_peak_v},
            {"periods", 2},
            {"transient_periods", 0},
            {"phase_pair", 0},
            {"crest_for", "current"}}},
          {"fixture",
           {{"clamp_pressure_bar", {{"lo", 4.5}, {"hi", 6.5}}},
            {"clamp_timeout_s", 2.0},
            {"release_timeout_s", 2.0}}},
          {"analysis",
           {{"f0_min_hz", band.window_lo},
            {"f0_max_hz", band.window_hi},
            {"q_min", 5},
            {"q_max", 500},
            {"frf_method", "transient_lpm"}}},
          {"limits", DesignLimits(n)},
          {"bond_index",
           {{"f0_exponent", 0.0},
            {"f0_ref_hz", n.f0_hz},
            {"residue_ref_ohm_per_s", n.ResidueOhmPerS()},
            {"residue_to_f0", b.residue_to_f0}}},
          {"conditions",
           {{"winding_temperature_c",
             {{"r_ref_ohm", n.r_ohm}, {"t_ref_c", o.t_ref_c}, {"lo", 0}, {"hi", 45}}},
            {"out_of_window", "error"}}},
          {"sequential", {{"extend_periods", 2}, {"max_extensions", 2}, {"confidence_z", 3}}},
          {"excitation_design", ExcitationDesignBlock(b, o, sigma)}};
}

double Median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t m = v.size() / 2;
  return v.size() % 2 ? v[m] : 0.5 * (v[m - 1] + v[m]);
}

double MedianOf(const std::vector<analysis::GoldenUnit>& golden, std::string_view name) {
  std::vector<double> v;
  for (const analysis::GoldenUnit& u : golden) {
    const auto it = u.values.find(std::string(name));
    if (it == u.values.end() || !std::isfinite(it->second) || !(it->second > 0.0))
      throw std::invalid_argument("golden unit " + u.label + ": has no positive " +
                                  std::string(name) +
                                  " (not analysable with the design's "
                                  "recipe?)");
    v.push_back(it->second);
  }
  return Median(v);
}

std::string Compare(std::string_view name, double design, double units, double tolerance) {
  const double off = units / design - 1.0;
  std::ostringstream m = analysis::MessageStream();
  m.precision(4);
  m << name << ": design " << design << " " << names::UnitOf(name) << ", golden units' median "
    << units << " (" << (off >= 0 ? "+" : "") << Fixed(100.0 * off, 1) << " %)";
  if (std::abs(off) > tolerance)
    m << " DISAGREES (more than " << Fixed(100.0 * tolerance, 0)
      << " %: check the motor file, or are the units another motor?)";
  return m.str();
}

}  // namespace

bool RecipeNewOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  for (const auto& [v, n] : {std::pair{sample_rate_hz, "sample_rate_hz"},
                             {noise_v_rms, "noise_v_rms"},
                             {noise_a_rms, "noise_a_rms"},
                             {max_peak_v, "max_peak_v"},
                             {current_full_scale_a, "current_full_scale_a"}})
    if (!(std::isfinite(v) && v > 0.0)) return fail(std::string(n) + " must be positive");
  if (!(shift_fraction > 0.0 && shift_fraction <= 0.1))
    return fail("shift_fraction must be in (0, 0.1] (a test's std(f0) as a share of the shift)");
  if (!(t_ref_c > -50.0 && t_ref_c < 150.0)) return fail("t_ref_c must be in (-50, 150) degC");
  return true;
}

RecipeBasis BasisFromMotor(const io::MotorSpec& motor) {
  const analysis::ClampedMotor m = motor.Motor();
  const analysis::ChainPrediction p =
      analysis::PredictChain(motor.r_ohm, motor.l_h, m.transmission_nm_per_a, motor.rotor);
  RecipeBasis b;
  b.motor_id = motor.id;
  b.poles = motor.poles > 0 ? motor.poles : motor.rotor.magnets;
  b.rotor_inertia_kg_m2 = p.total_inertia_kg_m2;
  b.nominal = p.good;
  b.f0_half_soft_hz = p.half_soft.f0_hz;
  b.f0_all_soft_hz = p.all_soft.f0_hz;
  b.residue_to_f0 = p.residue_to_f0;
  b.source =
      "the motor's chain (defect direction at a bond loss of " + Fixed(p.direction_loss, 3) + ")";
  return b;
}

Calibration CalibrateToGolden(const RecipeBasis& design,
                              const std::vector<analysis::GoldenUnit>& golden) {
  if (golden.size() < 3)
    throw std::invalid_argument("--golden: " + std::to_string(golden.size()) +
                                " units; calibrating the design needs at least 3");
  Calibration c;
  c.units = static_cast<int>(golden.size());
  c.basis = design;
  analysis::MotionalImpedance& n = c.basis.nominal;
  const analysis::MotionalImpedance& d = design.nominal;
  n.f0_hz = MedianOf(golden, names::kResonanceFHz);
  n.q = MedianOf(golden, names::kResonanceQ);
  n.r_ohm = MedianOf(golden, names::kWindingROhm);
  n.l_h = MedianOf(golden, names::kWindingLH);
  const double a = MedianOf(golden, names::kMotionalResidueOhmPerS);
  n.rp_ohm = a * n.q / (2.0 * std::numbers::pi * n.f0_hz);
  const double scale = n.f0_hz / d.f0_hz;
  c.basis.f0_half_soft_hz = design.f0_half_soft_hz * scale;
  c.basis.f0_all_soft_hz = design.f0_all_soft_hz * scale;
  c.basis.source =
      design.source + ", calibrated to the medians of " + std::to_string(c.units) + " golden units";
  c.disagreements = {Compare(names::kResonanceFHz, d.f0_hz, n.f0_hz, 0.05),
                     Compare(names::kResonanceQ, d.q, n.q, 0.2),
                     Compare(names::kWindingROhm, d.r_ohm, n.r_ohm, 0.2),
                     Compare(names::kWindingLH, d.l_h, n.l_h, 0.2),
                     Compare(names::kMotionalResidueOhmPerS, d.ResidueOhmPerS(), a, 0.2)};
  return c;
}

// The design for time, at the amplitude the hardware allows: when the shortest record meets the
// requirement with room to spare, DesignExcitationForTime lowers the amplitude to just meet it;
// here the requirement is tightened instead to what the full amplitude reaches in that record
// (the f0 requirement does not cover the residue and the second-mode test, which gain from it).
analysis::ExcitationDesign DesignAtFullAmplitude(const Recipe& skeleton) {
  const analysis::ExcitationRequirement& req = *skeleton.excitation_design;
  analysis::ExcitationDesign d = analysis::DesignExcitationForTime(skeleton.excitation, req);
  if (!d.usable || d.chosen.amplitude_limited_by != "requirement") return d;
  analysis::ExcitationRequirement probe = req;  // no record meets it: nothing is lowered
  probe.sigma_f0_hz = 1e-9 * req.sigma_f0_hz;
  for (const analysis::ExcitationCandidate& c :
       analysis::DesignExcitationForTime(skeleton.excitation, probe).candidates) {
    if (std::abs(c.line_spacing_hz - d.chosen.line_spacing_hz) > 1e-9) continue;
    analysis::ExcitationRequirement full = req;
    full.sigma_f0_hz = c.sigma_f0_one_period_hz / std::sqrt(d.chosen.periods) * (1.0 + 1e-6);
    analysis::ExcitationDesign at_full =
        analysis::DesignExcitationForTime(skeleton.excitation, full);
    at_full.chosen.amplitude_limited_by = c.amplitude_limited_by;  // not lowered (1e-6 aside)
    return at_full;
  }
  return d;
}

Recipe WithDesignedExcitation(Recipe next, const analysis::ExcitationDesign& d) {
  next.excitation = d.excitation;
  next.periods = d.chosen.periods;
  next.transient_periods = 0;
  next.analysis.frf_method = analysis::FrfMethod::kTransientLpm;
  next.analysis.frf.transient_periods = 0;
  return next;
}

RecipeProposal ProposeRecipe(const RecipeBasis& b, const RecipeNewOptions& o,
                             const std::string& id) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("options: " + why);
  const double shift = b.nominal.f0_hz - b.f0_half_soft_hz;
  if (!(shift > 0.0))
    throw std::invalid_argument(
        "the chain's half-soft rotor does not ring lower than the good "
        "one (" +
        Fixed(b.f0_half_soft_hz, 1) + " against " + Fixed(b.nominal.f0_hz, 1) +
        " Hz): no requirement to derive");
  RecipeProposal p;
  p.basis = b;
  p.required_sigma_f0_hz = o.shift_fraction * shift;
  const Band band = BandFor(b, o);
  const Recipe skeleton = ParseRecipe(Skeleton(b, o, band, p.required_sigma_f0_hz, id),
                                      "recipe-new", {.check_excitation_design = false});
  const analysis::ExcitationDesign d = DesignAtFullAmplitude(skeleton);
  if (!d.usable)
    throw std::invalid_argument("no excitation meets the requirement: " + d.message +
                                " (raise --max-peak-v or --current-full-scale-a, or a larger "
                                "--shift-fraction)");
  Recipe next = WithDesignedExcitation(skeleton, d);
  next.excitation_design->sigma_f0_hz = d.required_sigma_f0_hz;
  next.conditions.excitation_v_rms = {0.8 * d.chosen.v_rms, 1.25 * d.chosen.v_rms, 0.0};
  next.conditions.excitation_a_rms = {0.5 * d.chosen.a_rms, 2.0 * d.chosen.a_rms, 0.0};
  next.approval = RecipeApproval{"proposed", "eol recipe-new", db::UtcNowIso8601(), ""};
  p.chosen = d.chosen;
  p.notes = {
      "mode: the good rotor rings at " + Fixed(b.nominal.f0_hz, 1) + " Hz (Q " +
          Fixed(b.nominal.q, 1) + ", Rp " + Fixed(b.nominal.rp_ohm, 3) + " ohm, residue " +
          Fixed(b.nominal.ResidueOhmPerS(), 2) + " ohm/s); half the magnets poorly bonded " +
          Fixed(b.f0_half_soft_hz, 1) + " Hz, all " + Fixed(b.f0_all_soft_hz, 1) + " Hz",
      "band: " + Fixed(band.f_lo, 0) + "-" + Fixed(band.f_hi, 0) +
          " Hz (an octave either side of the mode); f0 window " + Fixed(band.window_lo, 0) + "-" +
          Fixed(band.window_hi, 0) + " Hz",
      "requirement: std(f0) " + Fixed(p.required_sigma_f0_hz, 4) + " Hz at the nominal motor = " +
          json(o.shift_fraction).dump() + " x the half-soft rotor's shift of " + Fixed(shift, 2) +
          " Hz; the shortest record meeting it at full amplitude reaches " +
          Fixed(d.required_sigma_f0_hz, 4) + " Hz (the recipe's sigma_f0_hz)",
      "excitation: " + Fixed(d.chosen.line_spacing_hz, 4) + " Hz lines, " +
          Fixed(d.chosen.peak_v, 2) + " V peak (limited by " + d.chosen.amplitude_limited_by +
          "), " + std::to_string(d.chosen.periods) +
          " periods from rest = " + Fixed(d.chosen.record_s, 3) + " s per phase pair, std(f0) " +
          Fixed(d.chosen.sigma_f0_hz, 4) + " Hz",
      "conditions: winding r_ref_ohm " + Fixed(b.nominal.r_ohm, 4) + " ohm at " +
          Fixed(o.t_ref_c, 1) + " degC; excitation windows from the designed drive (" +
          Fixed(d.chosen.v_rms, 3) + " V rms, " + Fixed(d.chosen.a_rms, 3) + " A rms)",
      "bond index: residue_to_f0 " + Fixed(b.residue_to_f0, 2) +
          " from the chain (d ln residue / -d ln f0 as every bond softens); exponent 0 until "
          "taught",
      "limits: design limits around the nominal motor, no masks: eol teach replaces them"};
  next.description += " " + p.notes[2] + "; " + p.notes[3] + "; " + p.notes[5] + ".";
  p.recipe = RecipeToJson(next);
  ParseRecipe(p.recipe, id + " (proposed)");  // validated, the excitation's bound re-checked
  return p;
}

}  // namespace eol::station
