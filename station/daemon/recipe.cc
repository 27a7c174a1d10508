#include "station/daemon/recipe.h"

#include <openssl/evp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <string_view>
#include <tuple>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "drivers/io/json_config.h"

namespace eol::station {
namespace {

using analysis::Fixed;
using io::ConfigError;
using io::JsonObject;

void ParseExcitation(const JsonObject& e, Recipe& r) {
  r.excitation.f_lo_hz = e.RequiredNumber("f_lo_hz");
  r.excitation.f_hi_hz = e.RequiredNumber("f_hi_hz");
  r.excitation.line_spacing_hz = e.RequiredNumber("line_spacing_hz");
  r.excitation.sample_rate_hz = e.RequiredNumber("sample_rate_hz");
  r.excitation.peak_v = e.RequiredNumber("peak_v");
  r.excitation.crest_iterations = e.Integer("crest_iterations", r.excitation.crest_iterations);
  const std::string crest_for = e.String("crest_for", "voltage");
  e.Require(crest_for == "voltage" || crest_for == "current", "crest_for",
            "must be \"voltage\" or \"current\"");
  r.crest_for_current = crest_for == "current";
  const int periods = e.Integer("periods", 4);
  const int transient = e.Integer("transient_periods", 1);
  std::vector<int> pairs;
  e.Require(!(e.Has("phase_pair") && e.Has("phase_pairs")), "phase_pairs",
            "give phase_pair or phase_pairs, not both");
  if (e.Has("phase_pairs")) {
    const nlohmann::json& list = e.Raw("phase_pairs");
    e.Require(list.is_array() && !list.empty() && list.size() <= 3, "phase_pairs",
              "must be a list of 1 to 3 phase pairs");
    for (const nlohmann::json& p : list) {
      e.Require(p.is_number_integer(), "phase_pairs", "must hold integers 0, 1 or 2");
      pairs.push_back(p.get<int>());
    }
  } else {
    pairs.push_back(e.Integer("phase_pair", 0));
  }
  e.Require(r.excitation.f_lo_hz > 0, "f_lo_hz", "must be positive");
  e.Require(r.excitation.f_hi_hz > r.excitation.f_lo_hz, "f_hi_hz",
            "must be greater than " + e.PathOf("f_lo_hz"));
  e.Require(r.excitation.sample_rate_hz >= 2.5 * r.excitation.f_hi_hz, "sample_rate_hz",
            "must be at least 2.5 x f_hi_hz (anti-alias margin)");
  e.Require(r.excitation.peak_v > 0 && r.excitation.peak_v <= 50, "peak_v", "must be in (0, 50] V");
  // Resource bounds: a recipe must not be able to exhaust the station's memory or time.
  e.Require(r.excitation.sample_rate_hz <= kMaxSampleRateHz, "sample_rate_hz",
            "must be at most " + Fixed(kMaxSampleRateHz, 0) + " Hz (the fastest supported DAQ)");
  e.Require(r.excitation.line_spacing_hz >= kMinLineSpacingHz, "line_spacing_hz",
            "must be at least " + Fixed(kMinLineSpacingHz, 2) + " Hz (a period of at most " +
                Fixed(1.0 / kMinLineSpacingHz, 0) + " s)");
  e.Require(r.excitation.sample_rate_hz / r.excitation.line_spacing_hz <= kMaxPeriodSamples,
            "sample_rate_hz",
            "gives more than " + std::to_string(static_cast<long>(kMaxPeriodSamples)) +
                " samples per period (sample_rate_hz / line_spacing_hz)");
  e.Require(
      r.excitation.crest_iterations >= 0 && r.excitation.crest_iterations <= kMaxCrestIterations,
      "crest_iterations", "must be in [0, " + std::to_string(kMaxCrestIterations) + "]");
  e.Require(periods >= 2 && periods <= 1000, "periods", "must be in [2, 1000]");
  e.Require(transient >= 0 && transient <= 100, "transient_periods", "must be in [0, 100]");
  const double excitation_s =
      static_cast<double>(periods + transient) / r.excitation.line_spacing_hz;
  e.Require(excitation_s <= kMaxExcitationS, "periods",
            "(periods + transient_periods) / line_spacing_hz is " + Fixed(excitation_s, 1) +
                " s of excitation per phase pair; at most " + Fixed(kMaxExcitationS, 0) +
                " s are allowed");
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    e.Require(pairs[i] >= 0 && pairs[i] <= 2, e.Has("phase_pairs") ? "phase_pairs" : "phase_pair",
              "must be 0 (U-V), 1 (V-W) or 2 (W-U)");
    for (std::size_t j = 0; j < i; ++j)
      e.Require(pairs[i] != pairs[j], "phase_pairs", "names a phase pair twice");
  }
  std::string why;
  e.Require(r.excitation.IsValid(&why), "line_spacing_hz", why);
  r.periods = static_cast<std::size_t>(periods);
  r.transient_periods = static_cast<std::size_t>(transient);
  r.analysis.frf.transient_periods = r.transient_periods;
  r.phase_pairs.clear();
  for (int p : pairs) r.phase_pairs.push_back(static_cast<drivers::PhasePair>(p));
  r.phase_pair = r.phase_pairs.front();
  e.RejectUnknown();
}

void ParseFixture(const JsonObject& f, Recipe& r) {
  const JsonObject p = f.Object("clamp_pressure_bar");
  r.clamp_pressure_lo_bar = p.RequiredNumber("lo");
  r.clamp_pressure_hi_bar = p.RequiredNumber("hi");
  p.Require(r.clamp_pressure_lo_bar > 0, "lo", "must be positive");
  p.Require(r.clamp_pressure_hi_bar > r.clamp_pressure_lo_bar, "hi",
            "must be greater than " + p.PathOf("lo"));
  // The window is a safety interlock: one so wide that any pressure passes checks nothing.
  p.Require(r.clamp_pressure_lo_bar >= kMinClampPressureBar, "lo",
            "must be at least " + Fixed(kMinClampPressureBar, 1) +
                " bar (a clamp below it does not hold the shaft)");
  p.Require(r.clamp_pressure_hi_bar <= kMaxClampPressureBar, "hi",
            "must be at most " + Fixed(kMaxClampPressureBar, 0) + " bar");
  p.Require(r.clamp_pressure_hi_bar <= kMaxClampPressureRatio * r.clamp_pressure_lo_bar, "hi",
            "must be at most " + Fixed(kMaxClampPressureRatio, 0) + " x " + p.PathOf("lo") +
                " (a wider window does not check the clamp)");
  p.RejectUnknown();
  r.clamp_timeout_s = f.Number("clamp_timeout_s", r.clamp_timeout_s);
  r.release_timeout_s = f.Number("release_timeout_s", r.release_timeout_s);
  f.Require(r.clamp_timeout_s > 0 && r.clamp_timeout_s <= 60, "clamp_timeout_s",
            "must be in (0, 60] s");
  f.Require(r.release_timeout_s > 0 && r.release_timeout_s <= 60, "release_timeout_s",
            "must be in (0, 60] s");
  f.RejectUnknown();
}

// How to move the band with the window (the excitation is then designed again for it).
constexpr const char* kMoveBandToo =
    " too (the band and the window move together; with an \"excitation_design\" block, run eol "
    "design-excitation on the edited recipe to design the excitation for the new band)";

void ParseAnalysis(const JsonObject& a, Recipe& r) {
  analysis::ResonanceFitOptions& fit = r.analysis.fit;
  fit.f0_min_hz = a.Number("f0_min_hz", r.excitation.f_lo_hz);
  fit.f0_max_hz = a.Number("f0_max_hz", r.excitation.f_hi_hz);
  fit.q_min = a.Number("q_min", fit.q_min);
  fit.q_max = a.Number("q_max", fit.q_max);
  const std::string band = "[" + Fixed(r.excitation.f_lo_hz, 1) + ", " +
                           Fixed(r.excitation.f_hi_hz, 1) + "] Hz (/excitation/f_lo_hz, f_hi_hz)";
  a.Require(fit.f0_min_hz >= r.excitation.f_lo_hz, "f0_min_hz",
            "must lie inside the excited band " + band + ": the fit only sees excited lines; " +
                "move /excitation/f_lo_hz down to " + Fixed(fit.f0_min_hz, 1) + " Hz or below" +
                kMoveBandToo);
  a.Require(fit.f0_max_hz <= r.excitation.f_hi_hz, "f0_max_hz",
            "must lie inside the excited band " + band + ": the fit only sees excited lines; " +
                "move /excitation/f_hi_hz up to " + Fixed(fit.f0_max_hz, 1) + " Hz or above" +
                kMoveBandToo);
  a.Require(fit.f0_max_hz > fit.f0_min_hz, "f0_max_hz", "must be above f0_min_hz");
  a.Require(fit.q_min > 0 && fit.q_max > fit.q_min, "q_max", "must be above q_min > 0");
  std::string why;
  a.Require(fit.IsValid(&why), "f0_min_hz", why);
  const std::string method =
      a.String("frf_method", analysis::ToString(analysis::FrfMethod::kDiscardTransient));
  a.Require(analysis::ParseFrfMethod(method, &r.analysis.frf_method), "frf_method",
            "must be \"discard_transient\" or \"transient_lpm\"");
  a.RejectUnknown();
}

// A resonance limit outside the analysis' f0 window (itself inside the excited band) can never
// be met or never fail: the fit reports no f0 outside the window.
void RequireInsideF0Window(const JsonObject& l, const analysis::MeasurementSpec& s,
                           const Recipe& r) {
  if (s.name != analysis::names::kResonanceFHz &&
      s.name != analysis::names::kResonanceFRefPressureHz)
    return;
  const analysis::ResonanceFitOptions& fit = r.analysis.fit;
  for (auto [key, bound] : {std::pair{"lo", s.limit.lo}, std::pair{"hi", s.limit.hi}}) {
    if (!bound) continue;
    l.Require(*bound >= fit.f0_min_hz && *bound <= fit.f0_max_hz, key,
              "is " + Fixed(*bound, 3) + " Hz, outside the analysis f0 window [" +
                  Fixed(fit.f0_min_hz, 1) + ", " + Fixed(fit.f0_max_hz, 1) +
                  "] Hz (/analysis/f0_min_hz, f0_max_hz) inside the excited band [" +
                  Fixed(r.excitation.f_lo_hz, 1) + ", " + Fixed(r.excitation.f_hi_hz, 1) +
                  "] Hz: the fit reports no resonance there; put the limit inside the window, "
                  "or move the window and the band around the motor's resonance");
  }
}

void ParseLimits(const nlohmann::json& limits, const std::string& path, Recipe& r) {
  if (!limits.is_array() || limits.empty())
    throw ConfigError(path + ": must be a non-empty array of limits");
  for (std::size_t i = 0; i < limits.size(); ++i) {
    const JsonObject l(limits[i], path + "/" + std::to_string(i));
    analysis::MeasurementSpec s;
    s.name = l.RequiredString("name");
    const auto& all = analysis::names::kAll;
    std::string known;
    for (auto n : all) known += (known.empty() ? "" : ", ") + std::string(n);
    l.Require(std::find(all.begin(), all.end(), s.name) != all.end(), "name",
              "is not a measurement the analysis produces (known: " + known + ")");
    for (const auto& other : r.limits) l.Require(other.name != s.name, "name", "is declared twice");
    // The measurement owns its unit: a limit may leave it out (or empty), or state the same.
    const std::string unit(analysis::names::UnitOf(s.name));
    s.unit = l.String("unit", "");
    l.Require(s.unit.empty() || s.unit == unit, "unit",
              "is \"" + s.unit + "\", but " + s.name + " is measured in \"" + unit +
                  "\": give lo and hi in " + unit + " with \"unit\": \"" + unit +
                  "\" (or leave unit out; the measurement owns its unit)");
    s.unit = unit;
    s.doc = l.String("doc", "");
    s.limit.lo = l.OptionalNumber("lo");
    s.limit.hi = l.OptionalNumber("hi");
    s.limit.marginal = l.Number("marginal", 0.0);
    l.Require(s.limit.lo || s.limit.hi, "lo", "a limit needs lo, hi or both");
    l.Require(!(s.limit.lo && s.limit.hi) || *s.limit.hi > *s.limit.lo, "hi",
              "must be greater than lo");
    l.Require(s.limit.marginal >= 0, "marginal", "must not be negative");
    RequireInsideF0Window(l, s, r);
    l.RejectUnknown();
    r.limits.push_back(s);
  }
}

void ParseMasks(const nlohmann::json& masks, const std::string& path, Recipe& r) {
  if (!masks.is_array()) throw ConfigError(path + ": must be an array of masks");
  if (masks.size() > kMaxMasks)
    throw ConfigError(path + ": must hold at most " + std::to_string(kMaxMasks) + " masks");
  for (std::size_t i = 0; i < masks.size(); ++i) {
    const JsonObject m(masks[i], path + "/" + std::to_string(i));
    analysis::CurveMask mask;
    mask.name = m.RequiredString("name");
    const bool name_ok =
        !mask.name.empty() && mask.name.size() <= 40 &&
        mask.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") == std::string::npos;
    m.Require(name_ok, "name", "must be 1 to 40 of a-z, 0-9 and _");
    for (const auto& other : r.masks)
      m.Require(other.name != mask.name, "name", "is declared twice");
    const std::string q = m.String("quantity", "re_ohm");
    m.Require(q == "re_ohm" || q == "abs_ohm", "quantity", "must be re_ohm or abs_ohm");
    mask.quantity =
        q == "re_ohm" ? analysis::MaskQuantity::kReOhm : analysis::MaskQuantity::kAbsOhm;
    mask.max_lines_outside = m.Integer("max_lines_outside", 0);
    mask.guard_sigma = m.Number("guard_sigma", 0.0);
    const nlohmann::json& pts = m.Raw("points");
    if (!pts.is_array()) throw ConfigError(m.PathOf("points") + ": must be an array of points");
    m.Require(pts.size() <= kMaxMaskPoints, "points",
              "must hold at most " + std::to_string(kMaxMaskPoints) + " points");
    for (std::size_t k = 0; k < pts.size(); ++k) {
      const JsonObject p(pts[k], m.PathOf("points") + "/" + std::to_string(k));
      analysis::MaskPoint point;
      point.f_hz = p.RequiredNumber("f_hz");
      point.lo = p.OptionalNumber("lo");
      point.hi = p.OptionalNumber("hi");
      p.RejectUnknown();
      mask.points.push_back(point);
    }
    std::string why;
    m.Require(mask.IsValid(&why), "points", why);
    m.RejectUnknown();
    r.masks.push_back(mask);
  }
}

analysis::Limit ParseWindow(const JsonObject& w) {
  analysis::Limit l;
  l.lo = w.OptionalNumber("lo");
  l.hi = w.OptionalNumber("hi");
  w.Require(!(l.lo && l.hi) || *l.hi > *l.lo, "hi", "must be greater than lo");
  return l;
}

void ParseConditions(const JsonObject& c, Recipe& r) {
  ConditionWindows& w = r.conditions;
  w.enabled = true;
  if (auto t = c.OptionalObject("winding_temperature_c")) {
    w.r_ref_ohm = t->RequiredNumber("r_ref_ohm");
    w.t_ref_c = t->Number("t_ref_c", w.t_ref_c);
    t->Require(w.r_ref_ohm > 0, "r_ref_ohm", "must be positive");
    t->Require(w.t_ref_c > -50 && w.t_ref_c < 200, "t_ref_c", "must be in (-50, 200) degC");
    w.winding_temperature_c = ParseWindow(*t);
    t->RejectUnknown();
  }
  if (auto v = c.OptionalObject("excitation_v_rms")) {
    w.excitation_v_rms = ParseWindow(*v);
    v->RejectUnknown();
  }
  if (auto a = c.OptionalObject("excitation_a_rms")) {
    w.excitation_a_rms = ParseWindow(*a);
    a->RejectUnknown();
  }
  const std::string policy = c.String("out_of_window", "error");
  c.Require(policy == "error" || policy == "record", "out_of_window",
            "must be \"error\" or \"record\" (R is not normalised to t_ref_c: the temperature "
            "is estimated from R itself, see station/daemon/conditions.h)");
  w.error_when_out = policy == "error";
  c.RejectUnknown();
}

bool DeclaresLimit(const Recipe& r, std::string_view name) {
  return std::any_of(r.limits.begin(), r.limits.end(),
                     [&](const analysis::MeasurementSpec& s) { return s.name == name; });
}

void ParseBondIndex(const JsonObject& o, Recipe& r) {
  analysis::BondIndexDefinition d;
  d.f0_exponent = o.RequiredNumber("f0_exponent");
  d.f0_ref_hz = o.RequiredNumber("f0_ref_hz");
  d.residue_ref_ohm_per_s = o.RequiredNumber("residue_ref_ohm_per_s");
  d.f0_name = o.String("f0", d.f0_name);
  d.residue_to_f0 = o.Number("residue_to_f0", d.residue_to_f0);
  o.Require(d.residue_to_f0 > 0.0 && d.residue_to_f0 <= analysis::kMaxResidueToF0, "residue_to_f0",
            "must be in (0, 1000]: d ln(residue) / -d ln(f0) of this motor's softer bonds (12 for "
            "the ten-pole motor; analysis/qc/bond_index.h)");
  o.Require(d.f0_name == analysis::names::kResonanceFHz ||
                d.f0_name == analysis::names::kResonanceFRefPressureHz,
            "f0", "must be resonance_f_hz or resonance_f_ref_pressure_hz");
  o.Require(d.f0_exponent >= 0.0 && d.f0_exponent <= 1000.0, "f0_exponent", "must be in [0, 1000]");
  o.Require(d.f0_ref_hz > 0.0, "f0_ref_hz", "must be positive");
  o.Require(d.residue_ref_ohm_per_s > 0.0, "residue_ref_ohm_per_s", "must be positive");
  std::string why;
  o.Require(d.IsValid(&why), "f0_exponent", why);  // finite (the checks above pass NaN)
  o.RejectUnknown();
  r.bond_index = d;
}

void ParseF0Pressure(const JsonObject& o, Recipe& r) {
  analysis::F0PressureDefinition d;
  d.exponent = o.RequiredNumber("exponent");
  d.pressure_ref_bar = o.RequiredNumber("pressure_ref_bar");
  std::string why;
  o.Require(d.exponent > 0.0 && d.exponent <= 0.5 && std::isfinite(d.exponent), "exponent",
            "must be in (0, 0.5] (f0 ~ sqrt(k), the clamp's k at most ~ p)");
  o.Require(d.IsValid(&why), "pressure_ref_bar", why);
  o.RejectUnknown();
  r.f0_pressure = d;
}

// What sigma_f0_hz is and how to choose it for a motor (the refusal's second half).
std::string HowToChooseSigmaF0(const Recipe& r) {
  std::string text =
      "sigma_f0_hz is the std(f0) one test must reach at the nominal motor, chosen per motor "
      "(the ten-pole recipes' 0.0085 Hz is their 5 s recipe's bound, not a rule): for a new "
      "motor state it as a fraction of what the test must resolve, e.g. 1/10 of the good "
      "units' std(f0) (the test's noise then widens their spread by 0.5 %) or 1/3 of the f0 "
      "shift of the smallest defect worth catching";
  for (const analysis::MeasurementSpec& s : r.limits)
    if (s.name == analysis::names::kResonanceFHz && s.limit.lo && s.limit.hi)
      text += " (the resonance limits [" + Fixed(*s.limit.lo, 1) + ", " + Fixed(*s.limit.hi, 1) +
              "] Hz taken as +-3 std of good units give 1/10 of it = " +
              Fixed((*s.limit.hi - *s.limit.lo) / 60.0, 4) + " Hz)";
  return text;
}

void RequireNominalPasses(const JsonObject& o, const Recipe& r,
                          const analysis::MotionalImpedance& n) {
  const std::string why = NominalDisagreement(r, n);
  o.Require(why.empty(), "nominal", why);
}

}  // namespace

std::string NominalDisagreement(const Recipe& r, const analysis::MotionalImpedance& n) {
  namespace names = analysis::names;
  std::map<std::string, analysis::Estimate> values = {
      {std::string(names::kResonanceFHz), {n.f0_hz, 0.0}},
      {std::string(names::kResonanceFRefPressureHz), {n.f0_hz, 0.0}},
      {std::string(names::kResonanceQ), {n.q, 0.0}},
      {std::string(names::kWindingROhm), {n.r_ohm, 0.0}},
      {std::string(names::kWindingLH), {n.l_h, 0.0}},
      {std::string(names::kMotionalRpOhm), {n.rp_ohm, 0.0}},
      {std::string(names::kMotionalResidueOhmPerS), {n.ResidueOhmPerS(), 0.0}}};
  if (r.bond_index) analysis::AddBondIndex(values, *r.bond_index);
  std::vector<analysis::MeasurementSpec> judged;
  for (const analysis::MeasurementSpec& s : r.limits)
    if (values.count(s.name)) judged.push_back(s);
  const analysis::Verdict v = analysis::Judge(judged, values);
  std::string why;
  for (const analysis::Reason& reason : v.reasons) why += (why.empty() ? "" : "; ") + reason.text;
  if (v.outcome != analysis::Outcome::kPass)
    return "the recipe's own nominal motor (the good motor it expects) fails its limits: " + why +
           ". The limits and the nominal describe different motors: teach the limits from "
           "this motor's golden units (eol teach) or correct the nominal (`eol recipe-new "
           "--golden` calibrates it to measured good units)";
  const ConditionWindows& w = r.conditions;
  if (w.r_ref_ohm <= 0.0) return "";
  const double t = WindingTemperatureC(n.r_ohm, w.r_ref_ohm, w.t_ref_c);
  const bool inside = (!w.winding_temperature_c.lo || t >= *w.winding_temperature_c.lo) &&
                      (!w.winding_temperature_c.hi || t <= *w.winding_temperature_c.hi);
  if (inside) return "";
  return "the nominal winding r_ohm " + Fixed(n.r_ohm, 4) +
         " ohm reads as a winding temperature of " + Fixed(t, 1) +
         " degC against /conditions/winding_temperature_c (r_ref_ohm " + Fixed(w.r_ref_ohm, 4) +
         " ohm at " + Fixed(w.t_ref_c, 1) +
         " degC), outside its window: r_ref_ohm is another motor's; set it to this motor's "
         "winding R at t_ref_c (eol teach relearns it from golden units)";
}

namespace {

// After the excitation and the analysis: the recipe's own excitation must meet the requirement
// it states.
void ParseExcitationDesign(const JsonObject& o, Recipe& r, bool check_excitation) {
  analysis::ExcitationRequirement d;
  d.sigma_f0_hz = o.RequiredNumber("sigma_f0_hz");
  d.verdict_margin_hz = o.Number("verdict_margin_hz", d.verdict_margin_hz);
  d.margin_z = o.Number("margin_z", d.margin_z);
  d.noise_v_rms = o.RequiredNumber("noise_v_rms");
  d.noise_a_rms = o.RequiredNumber("noise_a_rms");
  d.max_peak_v = o.RequiredNumber("max_peak_v");
  d.current_full_scale_a = o.Number("current_full_scale_a", d.current_full_scale_a);
  d.max_v_rms = o.Number("max_v_rms", d.max_v_rms);
  d.max_a_rms = o.Number("max_a_rms", d.max_a_rms);
  d.lines_per_half_power_band = o.Number("lines_per_half_power_band", d.lines_per_half_power_band);
  d.min_periods = static_cast<std::size_t>(
      std::clamp(o.Integer("min_periods", static_cast<int>(d.min_periods)), 0, 100000));
  const JsonObject n = o.Object("nominal");
  d.nominal.r_ohm = n.RequiredNumber("r_ohm");
  d.nominal.l_h = n.RequiredNumber("l_h");
  d.nominal.rp_ohm = n.RequiredNumber("rp_ohm");
  d.nominal.f0_hz = n.RequiredNumber("f0_hz");
  d.nominal.q = n.RequiredNumber("q");
  n.RejectUnknown();
  o.Require(d.max_peak_v <= 50.0, "max_peak_v", "must be at most 50 V (as peak_v)");
  o.Require(d.nominal.f0_hz > r.excitation.f_lo_hz && d.nominal.f0_hz < r.excitation.f_hi_hz,
            "nominal", "f0_hz must lie inside the excitation band");
  std::string why;
  o.Require(d.IsValid(&why), "sigma_f0_hz", why);
  o.Require(r.excitation.peak_v <= d.max_peak_v * (1.0 + 1e-9), "max_peak_v",
            "is below the excitation's peak_v " + Fixed(r.excitation.peak_v, 3) + " V");
  o.RejectUnknown();
  r.excitation_design = d;
  if (r.crest_for_current) {
    // The phases keep both peaks within the design's limits: the voltage's and 0.8 of the
    // current's full scale (multisine.h, crest_current_weight_ohm).
    r.excitation.crest_load_ohm = [motor = d.nominal](double f_hz) { return motor.At(f_hz); };
    r.excitation.crest_current_weight_ohm =
        std::isfinite(d.current_full_scale_a)
            ? d.max_peak_v / (analysis::kCurrentHeadroom * d.current_full_scale_a)
            : 0.0;
  }
  RequireNominalPasses(o, r, d.nominal);
  if (!check_excitation) return;
  const double predicted = analysis::PredictedSigmaF0Hz(r.excitation, r.AnalysedPeriods(), d);
  o.Require(predicted <= d.RequiredSigmaF0Hz() * (1.0 + 1e-6), "sigma_f0_hz",
            "the excitation reaches std(f0) " + Fixed(predicted, 5) +
                " Hz at the nominal motor (Cramer-Rao bound), more than the " +
                Fixed(d.RequiredSigmaF0Hz(), 5) + " Hz required. " + HowToChooseSigmaF0(r) +
                "; then eol design-excitation designs the shortest excitation that meets it");
}

void ParseSequential(const JsonObject& o, Recipe& r) {
  SequentialPolicy p;
  const int extend = o.Integer("extend_periods", static_cast<int>(p.extend_periods));
  p.max_extensions = o.Integer("max_extensions", p.max_extensions);
  p.confidence_z = o.Number("confidence_z", p.confidence_z);
  o.Require(extend >= 2 && extend <= 1000, "extend_periods", "must be in [2, 1000]");
  o.Require(extend > static_cast<int>(r.transient_periods), "extend_periods",
            "must exceed the excitation's transient_periods (they are played and dropped)");
  o.Require(p.max_extensions >= 1 && p.max_extensions <= 5, "max_extensions", "must be in [1, 5]");
  o.Require(p.confidence_z > 0.0 && p.confidence_z <= 10.0, "confidence_z", "must be in (0, 10]");
  p.extend_periods = static_cast<std::size_t>(extend);
  const double worst_s =
      static_cast<double>(r.periods + r.transient_periods +
                          p.extend_periods * static_cast<std::size_t>(p.max_extensions)) /
      r.excitation.line_spacing_hz;
  o.Require(worst_s <= kMaxExcitationS, "extend_periods",
            "the longest sequential test excites a phase pair for " + Fixed(worst_s, 1) +
                " s; at most " + Fixed(kMaxExcitationS, 0) + " s are allowed");
  o.RejectUnknown();
  r.sequential = p;
}

void ParseApproval(const JsonObject& o, Recipe& r) {
  RecipeApproval a;
  a.state = o.String("state", "");
  o.Require(a.state == "proposed" || a.state == "approved", "state",
            "must be \"proposed\" or \"approved\"");
  for (auto [key, field, required] : {std::tuple{"by", &a.by, true}, std::tuple{"at", &a.at, true},
                                      std::tuple{"note", &a.note, false}}) {
    *field = o.String(key, "");
    if (!required && field->empty() && !o.Has(key)) continue;
    o.Require(!field->empty() && field->size() <= kMaxInstructionBytes, key,
              "must be 1 to " + std::to_string(kMaxInstructionBytes) + " bytes of text");
  }
  o.RejectUnknown();
  r.approval = a;
}

void ParseInstructions(const JsonObject& o, Recipe& r) {
  for (auto [key, text] :
       {std::pair{"fail", &r.instructions.fail}, std::pair{"error", &r.instructions.error},
        std::pair{"aborted", &r.instructions.aborted}}) {
    *text = o.String(key, *text);
    const bool control = std::any_of(text->begin(), text->end(), [](char ch) {
      return static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F;
    });
    o.Require(!text->empty() && text->size() <= kMaxInstructionBytes && !control, key,
              "must be 1 to " + std::to_string(kMaxInstructionBytes) +
                  " bytes of text without control characters");
  }
  o.RejectUnknown();
}

}  // namespace

std::vector<analysis::MeasurementSpec> Recipe::Specs() const {
  std::vector<analysis::MeasurementSpec> specs = limits;
  for (const auto& m : masks) specs.push_back(m.Spec());
  return specs;
}

std::string Sha256Hex(const std::string& data) {
  unsigned char digest[EVP_MAX_MD_SIZE];
  unsigned int len = 0;
  if (EVP_Digest(data.data(), data.size(), digest, &len, EVP_sha256(), nullptr) != 1)
    throw std::runtime_error("SHA-256 failed");
  std::string hex;
  char buf[3];
  for (unsigned int i = 0; i < len; ++i) {
    std::snprintf(buf, sizeof buf, "%02x", digest[i]);
    hex += buf;
  }
  return hex;
}

std::string CanonicalHash(const nlohmann::json& j) { return Sha256Hex(j.dump()); }

Recipe ParseRecipe(const nlohmann::json& j, const std::string& source,
                   const RecipeParseOptions& options) {
  try {
    const JsonObject root(j, "");
    Recipe r;
    r.id = root.RequiredString("id");
    root.Require(!r.id.empty() && r.id.size() <= 64, "id", "must be 1 to 64 characters");
    r.version = root.Integer("version", 0);
    root.Require(r.version >= 1, "version", "must be a whole number >= 1");
    r.description = root.String("description", "");
    const JsonObject motor = root.Object("motor");
    r.poles = motor.Integer("poles", r.poles);
    r.rotor_inertia_kg_m2 = motor.RequiredNumber("rotor_inertia_kg_m2");
    motor.Require(r.poles >= 2 && r.poles % 2 == 0, "poles", "must be an even number >= 2");
    motor.Require(r.rotor_inertia_kg_m2 > 0, "rotor_inertia_kg_m2", "must be positive");
    motor.RejectUnknown();
    ParseExcitation(root.Object("excitation"), r);
    ParseFixture(root.Object("fixture"), r);
    if (auto a = root.OptionalObject("analysis")) {
      ParseAnalysis(*a, r);
    } else {
      r.analysis.fit.f0_min_hz = r.excitation.f_lo_hz;
      r.analysis.fit.f0_max_hz = r.excitation.f_hi_hz;
    }
    if (auto retest = root.OptionalObject("retest")) {
      r.max_tests_per_serial = retest->Integer("max_tests_per_serial", r.max_tests_per_serial);
      retest->Require(r.max_tests_per_serial >= 0 && r.max_tests_per_serial <= 100,
                      "max_tests_per_serial", "must be in [0, 100] (0: no limit)");
      retest->RejectUnknown();
    }
    ParseLimits(root.Raw("limits"), "/limits", r);
    r.analysis.fit.second_mode_test = DeclaresLimit(r, analysis::names::kSecondModeChi2Drop);
    if (root.Has("masks")) ParseMasks(root.Raw("masks"), "/masks", r);
    if (auto c = root.OptionalObject("conditions")) ParseConditions(*c, r);
    if (auto i = root.OptionalObject("instructions")) ParseInstructions(*i, r);
    if (auto a = root.OptionalObject("approval")) ParseApproval(*a, r);
    if (auto b = root.OptionalObject("bond_index")) ParseBondIndex(*b, r);
    if (auto p = root.OptionalObject("f0_pressure")) ParseF0Pressure(*p, r);
    if (auto q = root.OptionalObject("sequential")) ParseSequential(*q, r);
    if (auto d = root.OptionalObject("excitation_design"))
      ParseExcitationDesign(*d, r, options.check_excitation_design);
    root.Require(!r.crest_for_current || r.excitation_design.has_value(), "excitation",
                 "crest_for \"current\" needs the \"excitation_design\" block: its nominal "
                 "motor is the load the phases are designed for");
    const bool index_declared = DeclaresLimit(r, analysis::names::kBondIndexPct);
    root.Require(!index_declared || r.bond_index.has_value(), "bond_index",
                 "is required when a limit is declared on bond_index_pct (eol teach sets it; "
                 "analysis/qc/bond_index.h)");
    root.Require(!r.bond_index ||
                     r.bond_index->f0_name != analysis::names::kResonanceFRefPressureHz ||
                     r.f0_pressure.has_value(),
                 "f0_pressure", "is required when bond_index weighs resonance_f_ref_pressure_hz");
    const bool f0_pressure_declared = DeclaresLimit(r, analysis::names::kResonanceFRefPressureHz);
    root.Require(!f0_pressure_declared || r.f0_pressure.has_value(), "f0_pressure",
                 "is required when a limit is declared on resonance_f_ref_pressure_hz (eol "
                 "teach sets it; analysis/qc/f0_pressure.h)");
    root.RejectUnknown();
    r.source = j;
    r.hash = CanonicalHash(j);
    return r;
  } catch (const ConfigError& e) {
    throw ConfigError("recipe " + source + ": " + e.what());
  }
}

Recipe LoadRecipe(const std::string& path) { return ParseRecipe(io::ReadJsonFile(path), path); }

void WriteRecipeFile(const std::string& path, const nlohmann::json& j) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error(tmp + ": cannot be written");
    out << j.dump(2) << "\n";
    out.flush();
    if (!out) throw std::runtime_error(tmp + ": writing failed");
  }
  std::filesystem::rename(tmp, path);
}

std::size_t Recipe::AnalysedPeriods() const {
  return analysis.frf_method == analysis::FrfMethod::kTransientLpm ? periods + transient_periods
                                                                   : periods;
}

std::string Recipe::WhyNotApproved() const {
  if (Approved()) return "";
  return "recipe " + id + " v" + std::to_string(version) + " is a proposal (" + approval->by +
         ", " + approval->at +
         "): an engineer approves it first (POST /api/recipe/approve or eol recipe-approve)";
}

// The emitting half of the field list above: every key ParseRecipe reads, in its schema.
namespace {

void PutWindow(nlohmann::json& j, const analysis::Limit& l) {
  if (l.lo) j["lo"] = *l.lo;
  if (l.hi) j["hi"] = *l.hi;
}

nlohmann::json ConditionsJson(const ConditionWindows& w) {
  nlohmann::json j = {{"out_of_window", w.error_when_out ? "error" : "record"}};
  if (w.r_ref_ohm > 0) {
    nlohmann::json t = {{"r_ref_ohm", w.r_ref_ohm}, {"t_ref_c", w.t_ref_c}};
    PutWindow(t, w.winding_temperature_c);
    j["winding_temperature_c"] = t;
  }
  if (w.excitation_v_rms.lo || w.excitation_v_rms.hi) {
    j["excitation_v_rms"] = nlohmann::json::object();
    PutWindow(j["excitation_v_rms"], w.excitation_v_rms);
  }
  if (w.excitation_a_rms.lo || w.excitation_a_rms.hi) {
    j["excitation_a_rms"] = nlohmann::json::object();
    PutWindow(j["excitation_a_rms"], w.excitation_a_rms);
  }
  return j;
}

}  // namespace

nlohmann::json ExcitationDesignJson(const analysis::ExcitationRequirement& d) {
  const analysis::MotionalImpedance& n = d.nominal;
  nlohmann::json j = {
      {"sigma_f0_hz", d.sigma_f0_hz},
      {"verdict_margin_hz", d.verdict_margin_hz},
      {"margin_z", d.margin_z},
      {"noise_v_rms", d.noise_v_rms},
      {"noise_a_rms", d.noise_a_rms},
      {"max_peak_v", d.max_peak_v},
      {"lines_per_half_power_band", d.lines_per_half_power_band},
      {"min_periods", d.min_periods},
      {"nominal",
       {{"r_ohm", n.r_ohm}, {"l_h", n.l_h}, {"rp_ohm", n.rp_ohm}, {"f0_hz", n.f0_hz}, {"q", n.q}}}};
  if (std::isfinite(d.current_full_scale_a)) j["current_full_scale_a"] = d.current_full_scale_a;
  if (std::isfinite(d.max_v_rms)) j["max_v_rms"] = d.max_v_rms;
  if (std::isfinite(d.max_a_rms)) j["max_a_rms"] = d.max_a_rms;
  return j;
}

nlohmann::json InstructionsJson(const OperatorInstructions& i) {
  return {{"fail", i.fail}, {"error", i.error}, {"aborted", i.aborted}};
}

nlohmann::json LimitJson(const analysis::MeasurementSpec& s) {
  nlohmann::json j = {{"name", s.name}, {"unit", s.unit}, {"doc", s.doc}};
  PutWindow(j, s.limit);
  j["marginal"] = s.limit.marginal;
  return j;
}

nlohmann::json BondIndexJson(const analysis::BondIndexDefinition& d) {
  nlohmann::json j = {{"f0_exponent", d.f0_exponent},
                      {"f0_ref_hz", d.f0_ref_hz},
                      {"residue_ref_ohm_per_s", d.residue_ref_ohm_per_s}};
  if (d.f0_name != analysis::BondIndexDefinition{}.f0_name) j["f0"] = d.f0_name;
  if (d.residue_to_f0 != analysis::kResidueToF0) j["residue_to_f0"] = d.residue_to_f0;
  return j;
}

nlohmann::json F0PressureJson(const analysis::F0PressureDefinition& d) {
  return {{"exponent", d.exponent}, {"pressure_ref_bar", d.pressure_ref_bar}};
}

nlohmann::json MaskJson(const analysis::CurveMask& m) {
  nlohmann::json points = nlohmann::json::array();
  for (const analysis::MaskPoint& p : m.points) {
    nlohmann::json pt = {{"f_hz", p.f_hz}};
    if (p.lo) pt["lo"] = *p.lo;
    if (p.hi) pt["hi"] = *p.hi;
    points.push_back(pt);
  }
  return {{"name", m.name},
          {"quantity", m.quantity == analysis::MaskQuantity::kReOhm ? "re_ohm" : "abs_ohm"},
          {"max_lines_outside", m.max_lines_outside},
          {"guard_sigma", m.guard_sigma},
          {"points", points}};
}

nlohmann::json RecipeToJson(const Recipe& r) {
  nlohmann::json pairs = nlohmann::json::array();
  for (drivers::PhasePair p : r.phase_pairs) pairs.push_back(static_cast<int>(p));
  nlohmann::json limits = nlohmann::json::array();
  for (const analysis::MeasurementSpec& s : r.limits) limits.push_back(LimitJson(s));
  nlohmann::json masks = nlohmann::json::array();
  for (const analysis::CurveMask& m : r.masks) masks.push_back(MaskJson(m));
  nlohmann::json j = {
      {"id", r.id},
      {"version", r.version},
      {"description", r.description},
      {"motor", {{"poles", r.poles}, {"rotor_inertia_kg_m2", r.rotor_inertia_kg_m2}}},
      {"excitation",
       {{"f_lo_hz", r.excitation.f_lo_hz},
        {"f_hi_hz", r.excitation.f_hi_hz},
        {"line_spacing_hz", r.excitation.line_spacing_hz},
        {"sample_rate_hz", r.excitation.sample_rate_hz},
        {"peak_v", r.excitation.peak_v},
        {"crest_iterations", r.excitation.crest_iterations},
        {"periods", r.periods},
        {"transient_periods", r.transient_periods},
        {"phase_pairs", pairs}}},
      {"fixture",
       {{"clamp_pressure_bar", {{"lo", r.clamp_pressure_lo_bar}, {"hi", r.clamp_pressure_hi_bar}}},
        {"clamp_timeout_s", r.clamp_timeout_s},
        {"release_timeout_s", r.release_timeout_s}}},
      {"analysis",
       {{"f0_min_hz", r.analysis.fit.f0_min_hz},
        {"f0_max_hz", r.analysis.fit.f0_max_hz},
        {"q_min", r.analysis.fit.q_min},
        {"q_max", r.analysis.fit.q_max},
        {"frf_method", analysis::ToString(r.analysis.frf_method)}}},
      {"retest", {{"max_tests_per_serial", r.max_tests_per_serial}}},
      {"limits", limits},
      {"masks", masks},
      {"instructions", InstructionsJson(r.instructions)}};
  if (r.conditions.enabled) j["conditions"] = ConditionsJson(r.conditions);
  if (r.crest_for_current) j["excitation"]["crest_for"] = "current";
  if (r.bond_index) j["bond_index"] = BondIndexJson(*r.bond_index);
  if (r.f0_pressure) j["f0_pressure"] = F0PressureJson(*r.f0_pressure);
  if (r.sequential)
    j["sequential"] = {{"extend_periods", r.sequential->extend_periods},
                       {"max_extensions", r.sequential->max_extensions},
                       {"confidence_z", r.sequential->confidence_z}};
  if (r.excitation_design) j["excitation_design"] = ExcitationDesignJson(*r.excitation_design);
  if (r.approval) {
    j["approval"] = {{"state", r.approval->state}, {"by", r.approval->by}, {"at", r.approval->at}};
    if (!r.approval->note.empty()) j["approval"]["note"] = r.approval->note;
  }
  return j;
}

}  // namespace eol::station
