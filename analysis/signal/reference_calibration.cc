#include "analysis/signal/reference_calibration.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>

#include "analysis/signal/fft.h"

namespace eol::analysis {

void DelayPeriodic(std::vector<double>& x, double delay_s, double sample_rate_hz) {
  if (delay_s == 0.0 || x.empty()) return;
  const std::size_t n = x.size();
  const RealFft fft(n);
  std::vector<std::complex<double>> spectrum = fft.Forward(x.data());
  const double shift = delay_s * sample_rate_hz / static_cast<double>(n);
  for (std::size_t k = 0; k < spectrum.size(); ++k)
    spectrum[k] *= std::polar(1.0, -2.0 * std::numbers::pi * static_cast<double>(k) * shift);
  if (n % 2 == 0) spectrum.back() = spectrum.back().real();
  x = fft.Inverse(spectrum);
}

bool ReferenceCalibrationOptions::IsValid(std::string* why) const {
  if (!(reference_ohm > 0.0) || !std::isfinite(reference_ohm)) {
    *why = "reference_ohm must be positive (got " + std::to_string(reference_ohm) + ")";
    return false;
  }
  if (!(max_gain_error > 1.0) || !std::isfinite(max_gain_error)) {
    *why = "max_gain_error must be greater than 1";
    return false;
  }
  return frf.IsValid(why);
}

ReferenceCalibrationSummary EstimateReferenceCalibration(
    const Frf& z, const ReferenceCalibrationOptions& options) {
  ReferenceCalibrationSummary s;
  s.z = z;
  std::string why;
  if (!options.IsValid(&why)) {
    s.message = "options: " + why;
    return s;
  }
  if (!z.Validate(&why)) {
    s.message = "impedance: " + why;
    return s;
  }
  if (z.quantity != Quantity::kImpedanceOhm) {
    s.message = "need an impedance, got " + std::string(ToString(z.quantity));
    return s;
  }
  const std::size_t n = z.size();
  s.lines = n;
  if (n < 3) {
    s.message = "need at least 3 lines, got " + std::to_string(n);
    return s;
  }
  std::vector<double> w(n), re(n), phi(n), v(n);
  for (std::size_t k = 0; k < n; ++k) {
    const double mag = std::abs(z.value[k]);
    if (!(mag > 0.0)) {
      s.message = "|Z| is 0 at " + std::to_string(z.freq_hz[k]) + " Hz";
      return s;
    }
    w[k] = 2.0 * std::numbers::pi * z.freq_hz[k];
    re[k] = std::log(mag / options.reference_ohm);
    phi[k] = std::arg(z.value[k]);
    if (k > 0) {  // unwrap along frequency
      while (phi[k] - phi[k - 1] > std::numbers::pi) phi[k] -= 2.0 * std::numbers::pi;
      while (phi[k] - phi[k - 1] < -std::numbers::pi) phi[k] += 2.0 * std::numbers::pi;
    }
    v[k] = z.has_sigma() ? z.sigma[k] * z.sigma[k] / (2.0 * mag * mag) : 1.0;
  }
  double sw = 0, swr = 0, sww = 0, swwp = 0;
  for (std::size_t k = 0; k < n; ++k) {
    sw += 1.0 / v[k];
    swr += re[k] / v[k];
    sww += w[k] * w[k] / v[k];
    swwp += w[k] * phi[k] / v[k];
  }
  const double ln_g = swr / sw;
  const double tau = swwp / sww;
  double chi_mag = 0, chi_phase = 0;
  for (std::size_t k = 0; k < n; ++k) {
    chi_mag += (re[k] - ln_g) * (re[k] - ln_g) / v[k];
    chi_phase += (phi[k] - w[k] * tau) * (phi[k] - w[k] * tau) / v[k];
  }
  const double dof = static_cast<double>(n - 1);
  s.magnitude_chi2_per_dof = chi_mag / dof;
  s.phase_chi2_per_dof = chi_phase / dof;
  const double scale_mag =
      z.has_sigma() ? std::max(1.0, s.magnitude_chi2_per_dof) : s.magnitude_chi2_per_dof;
  const double scale_phase =
      z.has_sigma() ? std::max(1.0, s.phase_chi2_per_dof) : s.phase_chi2_per_dof;
  s.gain = std::exp(ln_g);
  s.gain_sigma = s.gain * std::sqrt(scale_mag / sw);
  s.delay_s = tau;
  s.delay_sigma_s = std::sqrt(scale_phase / sww);
  if (s.gain > options.max_gain_error || s.gain < 1.0 / options.max_gain_error) {
    s.message = "gain " + std::to_string(s.gain) + " is beyond a factor " +
                std::to_string(options.max_gain_error) +
                " of 1: wrong reference_ohm, or the channels are wired wrongly";
    return s;
  }
  s.usable = true;
  s.message = "gain " + std::to_string(s.gain) + " +- " + std::to_string(s.gain_sigma) +
              ", current channel delay " + std::to_string(s.delay_s * 1e6) + " +- " +
              std::to_string(s.delay_sigma_s * 1e6) + " us over " + std::to_string(n) + " lines";
  return s;
}

ReferenceCalibrationSummary EstimateReferenceCalibration(
    const Recording& recording, const std::vector<std::size_t>& lines,
    const ReferenceCalibrationOptions& options) {
  const FrfSummary frf = EstimatePeriodicFrf(recording, lines, options.frf);
  if (!frf.usable) {
    ReferenceCalibrationSummary s;
    s.z = frf.frf;
    s.message = "impedance of the reference: " + frf.message;
    return s;
  }
  return EstimateReferenceCalibration(frf.frf, options);
}

}  // namespace eol::analysis
