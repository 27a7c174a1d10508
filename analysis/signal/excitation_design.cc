#include "analysis/signal/excitation_design.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "analysis/fit/cramer_rao.h"
#include "analysis/qc/line_measurement.h"
#include "analysis/signal/fft.h"

namespace eol::analysis {
namespace {

bool Positive(double x) { return std::isfinite(x) && x > 0.0; }

double Rms(const std::vector<double>& x) {
  double s = 0.0;
  for (double v : x) s += v * v;
  return std::sqrt(s / static_cast<double>(x.size()));
}

ExcitationDrive DriveOf(const Excitation& ex, const MotionalImpedance& motor) {
  const RealFft fft(ex.period_samples);
  std::vector<std::complex<double>> u = fft.Forward(ex.period_v.data());
  std::vector<std::complex<double>> i(u.size(), 0.0);
  for (std::size_t k : ex.lines)
    i[k] = u[k] / motor.At(static_cast<double>(k) * ex.line_spacing_hz);
  const std::vector<double> current = fft.Inverse(i);
  ExcitationDrive d;
  d.v_rms = Rms(ex.period_v);
  d.a_rms = Rms(current);
  for (double a : current) d.a_peak = std::max(d.a_peak, std::abs(a));
  return d;
}

ExcitationCandidate Evaluate(MultisineOptions o, const ExcitationRequirement& r) {
  ExcitationCandidate c;
  c.line_spacing_hz = o.line_spacing_hz;
  // The waveform's shape does not depend on its peak: design at 1 V, then scale.
  o.peak_v = 1.0;
  const Excitation unit = DesignMultisine(o);
  c.lines = unit.lines.size();
  const ExcitationDrive d = DriveOf(unit, r.nominal);
  struct Bound {
    double peak_v;
    const char* name;
  };
  const Bound bounds[] = {
      {r.max_peak_v, "max_peak_v"},
      {r.max_v_rms / d.v_rms, "max_v_rms"},
      {r.max_a_rms / d.a_rms, "max_a_rms"},
      {kCurrentHeadroom * r.current_full_scale_a / d.a_peak, "current_full_scale"}};
  c.peak_v = bounds[0].peak_v;
  c.amplitude_limited_by = bounds[0].name;
  for (const Bound& b : bounds)
    if (b.peak_v < c.peak_v) {
      c.peak_v = b.peak_v;
      c.amplitude_limited_by = b.name;
    }
  c.v_rms = d.v_rms * c.peak_v;
  c.a_rms = d.a_rms * c.peak_v;
  c.current_peak_a = d.a_peak * c.peak_v;
  // The bound at this peak, from the unit period scaled (the shape does not depend on the peak).
  Excitation scaled = unit;
  for (double& v : scaled.period_v) v *= c.peak_v;
  c.sigma_f0_one_period_hz = PredictedSigmaF0Hz(scaled, 1, r);
  if (!std::isfinite(c.sigma_f0_one_period_hz)) return c;
  // sigma_k^2 is proportional to 1/P, so the bound to 1/sqrt(P).
  const double needed = std::pow(c.sigma_f0_one_period_hz / r.RequiredSigmaF0Hz(), 2.0);
  c.periods =
      std::max<std::size_t>(r.min_periods, static_cast<std::size_t>(std::ceil(needed - 1e-9)));
  c.record_s = static_cast<double>(c.periods) / c.line_spacing_hz;
  c.sigma_f0_hz = c.sigma_f0_one_period_hz / std::sqrt(static_cast<double>(c.periods));
  if (c.periods == r.min_periods && c.sigma_f0_hz < r.RequiredSigmaF0Hz()) {
    // The record is at its floor: more amplitude would buy precision, not time. Lower it until
    // the bound (proportional to 1 / U) just meets the requirement.
    const double scale = c.sigma_f0_hz / r.RequiredSigmaF0Hz();
    c.peak_v *= scale;
    c.v_rms *= scale;
    c.a_rms *= scale;
    c.current_peak_a *= scale;
    c.sigma_f0_one_period_hz /= scale;
    c.sigma_f0_hz = r.RequiredSigmaF0Hz();
    c.amplitude_limited_by = "requirement";
  }
  c.meets = c.record_s <= r.max_record_s;
  return c;
}

}  // namespace

double ExcitationRequirement::RequiredSigmaF0Hz() const {
  double s = sigma_f0_hz;
  if (verdict_margin_hz > 0.0) s = std::min(s, verdict_margin_hz / margin_z);
  return s;
}

bool ExcitationRequirement::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!Positive(sigma_f0_hz)) return fail("sigma_f0_hz must be positive");
  if (!(std::isfinite(verdict_margin_hz) && verdict_margin_hz >= 0.0))
    return fail("verdict_margin_hz must be zero (none) or positive");
  if (!Positive(margin_z)) return fail("margin_z must be positive");
  if (!(Positive(nominal.r_ohm) && Positive(nominal.l_h) && Positive(nominal.rp_ohm) &&
        Positive(nominal.f0_hz) && Positive(nominal.q)))
    return fail("nominal: r_ohm, l_h, rp_ohm, f0_hz and q must be positive");
  if (!Positive(noise_v_rms) || !Positive(noise_a_rms))
    return fail("noise_v_rms and noise_a_rms must be positive (the DAQ's noise per sample)");
  if (!Positive(max_peak_v)) return fail("max_peak_v must be positive");
  if (!(max_v_rms > 0.0) || !(max_a_rms > 0.0) || !(current_full_scale_a > 0.0))
    return fail("max_v_rms, max_a_rms and current_full_scale_a must be positive");
  if (!(Positive(lines_per_half_power_band) && lines_per_half_power_band <= 100.0))
    return fail("lines_per_half_power_band must be in (0, 100]");
  if (min_periods < 1 || min_periods > 1000) return fail("min_periods must be 1 to 1000");
  if (!Positive(max_record_s)) return fail("max_record_s must be positive");
  return true;
}

ExcitationDrive DriveThrough(const MultisineOptions& excitation, const MotionalImpedance& motor) {
  return DriveOf(DesignMultisine(excitation), motor);
}

double PredictedSigmaF0Hz(const Excitation& excitation, std::size_t periods,
                          const ExcitationRequirement& r) {
  const LineMeasurementSetup setup =
      MakeLineMeasurement(excitation, periods, r.noise_v_rms, r.noise_a_rms);
  const Frf nominal = r.nominal.Evaluate(setup.freq_hz);
  const CramerRaoBound b =
      ComputeCramerRaoBound(r.nominal, setup.freq_hz, LineSigma(setup, nominal.value));
  return b.valid ? b.Std(kParamF0) : std::nan("");
}

double PredictedSigmaF0Hz(const MultisineOptions& excitation, std::size_t periods,
                          const ExcitationRequirement& r) {
  return PredictedSigmaF0Hz(DesignMultisine(excitation), periods, r);
}

ExcitationDesign DesignExcitationForTime(const MultisineOptions& base,
                                         const ExcitationRequirement& requirement) {
  std::string why;
  if (!requirement.IsValid(&why)) throw std::invalid_argument("excitation requirement: " + why);
  ExcitationDesign d;
  d.required_sigma_f0_hz = requirement.RequiredSigmaF0Hz();
  const double coarsest =
      LineSpacingForResonance(requirement.nominal.f0_hz, requirement.nominal.q, base.sample_rate_hz,
                              requirement.lines_per_half_power_band);
  for (double divide : {1.0, 2.0, 4.0}) {
    MultisineOptions o = base;
    // fs / (n * divide) keeps a whole number of samples per period.
    o.line_spacing_hz = base.sample_rate_hz / (std::round(base.sample_rate_hz / coarsest) * divide);
    o.peak_v = 1.0;
    if (!o.IsValid(&why)) continue;  // e.g. no line left in the band
    d.candidates.push_back(Evaluate(o, requirement));
  }
  const ExcitationCandidate* best = nullptr;
  for (const ExcitationCandidate& c : d.candidates)
    if (c.meets && (!best || c.record_s < best->record_s - 1e-9)) best = &c;
  if (!best) {
    d.message = "no record of at most " + std::to_string(requirement.max_record_s) +
                " s reaches std(f0) " + std::to_string(d.required_sigma_f0_hz) +
                " Hz at the amplitude the limits allow";
    return d;
  }
  d.chosen = *best;
  d.excitation = base;
  d.excitation.line_spacing_hz = best->line_spacing_hz;
  d.excitation.peak_v = best->peak_v;
  d.usable = true;
  d.message = "ok";
  return d;
}

}  // namespace eol::analysis
