#include "analysis/qc/line_measurement.h"

#include <algorithm>
#include <cmath>
#include <random>

#include "analysis/signal/fft.h"

namespace eol::analysis {

LineMeasurementSetup MakeLineMeasurement(const MultisineOptions& excitation, std::size_t periods,
                                         double voltage_noise_v, double current_noise_a) {
  return MakeLineMeasurement(DesignMultisine(excitation), periods, voltage_noise_v,
                             current_noise_a);
}

LineMeasurementSetup MakeLineMeasurement(const Excitation& ex, std::size_t periods,
                                         double voltage_noise_v, double current_noise_a) {
  const std::size_t n = ex.period_samples;
  const RealFft fft(n);
  const std::vector<std::complex<double>> u = fft.Forward(ex.period_v.data());
  const double nd = static_cast<double>(n);
  LineMeasurementSetup s;
  s.freq_hz = ex.LineFrequenciesHz();
  for (std::size_t k : ex.lines) s.u_amp_v.push_back(std::abs(u[k]) * 2.0 / nd);
  s.du2 = 4.0 * voltage_noise_v * voltage_noise_v / nd;
  s.di2 = 4.0 * current_noise_a * current_noise_a / nd;
  s.periods = periods;
  return s;
}

std::vector<double> LineSigma(const LineMeasurementSetup& s,
                              const std::vector<std::complex<double>>& z) {
  std::vector<double> sigma(z.size());
  for (std::size_t k = 0; k < z.size(); ++k) {
    const double zm = std::abs(z[k]);
    const double ua = s.u_amp_v[k];
    const double ia = ua / zm;
    const double rel = s.du2 / (ua * ua) + s.di2 / (ia * ia);
    sigma[k] = zm * std::sqrt(rel / static_cast<double>(s.periods));
  }
  return sigma;
}

Frf MeasureLineUnit(const LineMeasurementSetup& s, const std::vector<std::complex<double>>& z,
                    std::uint64_t seed, bool noise) {
  Frf f;
  f.freq_hz = s.freq_hz;
  f.sigma = LineSigma(s, z);
  f.quantity = Quantity::kImpedanceOhm;
  f.method = noise ? "periodic-eiv-fast" : "model";
  f.value = z;
  if (noise) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const double nu = 2.0 * static_cast<double>(s.periods > 1 ? s.periods - 1 : 1);
    std::chi_squared_distribution<double> chi2(nu);
    std::vector<double> ratio(z.size());
    for (std::size_t k = 0; k < z.size(); ++k) {
      const double sd = f.sigma[k] / std::sqrt(2.0);
      f.value[k] += std::complex<double>(sd * normal(rng), sd * normal(rng));
      ratio[k] = chi2(rng) / nu;
    }
    const std::size_t h = s.noise_smoothing_lines;
    for (std::size_t k = 0; k < z.size(); ++k) {
      const std::size_t a = k >= h ? k - h : 0, b = std::min(z.size(), k + h + 1);
      double mean = 0.0;
      for (std::size_t i = a; i < b; ++i) mean += ratio[i];
      f.sigma[k] *= std::sqrt(mean / static_cast<double>(b - a));
    }
  }
  return f;
}

}  // namespace eol::analysis
