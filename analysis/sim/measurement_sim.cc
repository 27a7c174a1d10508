#include "analysis/sim/measurement_sim.h"

#include <cmath>
#include <random>

#include "analysis/signal/fft.h"

namespace eol::analysis {

bool SimulatedMeasurementOptions::IsValid(std::string* why) const {
  if (periods < 2) {
    if (why) *why = "periods must be at least 2 (a sigma needs two periods)";
    return false;
  }
  if (!(voltage_noise_v >= 0.0 && current_noise_a >= 0.0)) {
    if (why) *why = "noise levels must not be negative";
    return false;
  }
  return true;
}

Recording SimulateImpedanceRecording(const ImpedanceFn& z, const Excitation& ex,
                                     const SimulatedMeasurementOptions& o) {
  const std::vector<double> i_period = SteadyStateCurrent(z, ex.period_v, ex.sample_rate_hz);
  const std::size_t n = ex.period_samples;
  const std::size_t total = n * (o.periods + o.transient_periods);
  Recording rec;
  rec.sample_rate_hz = ex.sample_rate_hz;
  rec.period_samples = n;
  rec.voltage_v.resize(total);
  rec.current_a.resize(total);
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> vn(0.0, 1.0);
  for (std::size_t t = 0; t < total; ++t) {
    rec.voltage_v[t] = ex.period_v[t % n] + o.voltage_noise_v * vn(rng);
    rec.current_a[t] = i_period[t % n] + o.current_noise_a * vn(rng);
  }
  return rec;
}

FrfSummary SimulateImpedanceMeasurement(const ImpedanceFn& z, const Excitation& ex,
                                        const SimulatedMeasurementOptions& o) {
  FrfSummary bad;
  std::string why;
  if (!o.IsValid(&why)) {
    bad.message = "invalid options: " + why;
    return bad;
  }
  PeriodicFrfOptions fo;
  fo.transient_periods = o.transient_periods;
  return EstimatePeriodicFrf(SimulateImpedanceRecording(z, ex, o), ex.lines, fo);
}

std::vector<double> ExpectedLineSigma(const ImpedanceFn& z, const Excitation& ex,
                                      const SimulatedMeasurementOptions& o) {
  const std::size_t n = ex.period_samples;
  const RealFft fft(n);
  const std::vector<std::complex<double>> u = fft.Forward(ex.period_v.data());
  const double nd = static_cast<double>(n);
  const double du2 = 4.0 * o.voltage_noise_v * o.voltage_noise_v / nd;
  const double di2 = 4.0 * o.current_noise_a * o.current_noise_a / nd;
  std::vector<double> sigma;
  for (std::size_t k : ex.lines) {
    const double f = static_cast<double>(k) * ex.sample_rate_hz / nd;
    const double u_amp = std::abs(u[k]) * 2.0 / nd;
    const double z_mag = std::abs(z(f));
    const double i_amp = u_amp / z_mag;
    const double rel = du2 / (u_amp * u_amp) + di2 / (i_amp * i_amp);
    sigma.push_back(z_mag * std::sqrt(rel / static_cast<double>(o.periods)));
  }
  return sigma;
}

}  // namespace eol::analysis
