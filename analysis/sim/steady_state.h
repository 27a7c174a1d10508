// Periodic steady state of a linear impedance driven by a periodic voltage.
//
// For a voltage period u with DFT U_k, the current period has I_k = U_k / Z(f_k) at every
// bin k (f_k = k fs / N; at DC Z(0) is taken as Z at a vanishing frequency, i.e. R for the
// motor model). This is exact for a stable linear system after its transient has died out,
// which is what the periodic estimator assumes and what the first dropped period absorbs.
#pragma once

#include <complex>
#include <functional>
#include <vector>

namespace eol::analysis {

using ImpedanceFn = std::function<std::complex<double>(double f_hz)>;

std::vector<double> SteadyStateCurrent(const ImpedanceFn& z, const std::vector<double>& period_v,
                                       double sample_rate_hz);

}  // namespace eol::analysis
