#include "analysis/sim/steady_state.h"

#include <stdexcept>

#include "analysis/signal/fft.h"

namespace eol::analysis {

std::vector<double> SteadyStateCurrent(const ImpedanceFn& z, const std::vector<double>& period_v,
                                       double sample_rate_hz) {
  const std::size_t n = period_v.size();
  if (n < 2) throw std::invalid_argument("SteadyStateCurrent: period must have 2+ samples");
  const RealFft fft(n);
  std::vector<std::complex<double>> u = fft.Forward(period_v.data());
  const double df = sample_rate_hz / static_cast<double>(n);
  for (std::size_t k = 0; k < u.size(); ++k) {
    if (u[k] == 0.0) continue;
    const double f = k == 0 ? 1e-3 * df : static_cast<double>(k) * df;
    u[k] /= z(f);
  }
  return fft.Inverse(u);
}

}  // namespace eol::analysis
