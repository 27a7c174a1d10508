// The station's impedance measurement of a line unit, in the frequency domain, for benchmarks
// that measure thousands of units.
//
// The recipe's multisine (multisine.h) is played for transient + P averaged periods, and the
// periodic errors-in-variables estimate (periodic_frf.h) of a linear motor in steady state with
// white channel noise (s_u V, s_i A rms per sample) is, at each excited line k,
//   Z_hat_k = Z_k + e_k,   e_k complex Gaussian, E|e_k|^2 = sigma_k^2,
//   sigma_k^2 = |Z_k|^2 / P (E|dU|^2 / |U_k|^2 + E|dI|^2 / |I_k|^2),
//   E|dU|^2 = 4 s_u^2 / N, E|dI|^2 = 4 s_i^2 / N, |I_k| = |U_k| / |Z_k|
// (analysis/sim/measurement_sim.h, ExpectedLineSigma; first order in the noise, which holds at
// the station's SNR of about 60 dB per line). Drawing e_k directly skips the time series and
// the FFTs: the same statistics at a hundredth of the cost.
// The reported sigma is estimated as the station estimates it: from the scatter of P periods
// (a variance ratio chi2_nu / nu per line, nu = 2(P - 1)), pooled over the 2h + 1 neighbouring
// lines (periodic_frf.h, h = noise_smoothing_lines), so the fit's chi2/dof scatters as on the
// station, not just as chi2 with known sigma.
#pragma once

#include <complex>
#include <cstdint>
#include <vector>

#include "analysis/frf.h"
#include "analysis/signal/multisine.h"

namespace eol::analysis {

struct LineMeasurementSetup {
  std::vector<double> freq_hz;  // the excited lines
  std::vector<double> u_amp_v;  // |U_k| of one period (DFT scaled by 2/N)
  double du2 = 0.0;             // E|dU|^2 per period, V^2
  double di2 = 0.0;             // E|dI|^2 per period, A^2
  std::size_t periods = 4;
  std::size_t noise_smoothing_lines = 5;  // h of periodic_frf.h
};

// Designs the multisine (throws std::invalid_argument when the options are invalid).
LineMeasurementSetup MakeLineMeasurement(const MultisineOptions& excitation, std::size_t periods,
                                         double voltage_noise_v, double current_noise_a);
// The same for an excitation already designed.
LineMeasurementSetup MakeLineMeasurement(const Excitation& excitation, std::size_t periods,
                                         double voltage_noise_v, double current_noise_a);

// sigma_k for the true impedance z on setup.freq_hz.
std::vector<double> LineSigma(const LineMeasurementSetup& setup,
                              const std::vector<std::complex<double>>& z);

// The measured Frf (method "periodic-eiv-fast"), with the estimated sigma. noise == false
// gives the exact z with the expected sigma (the expected measurement).
Frf MeasureLineUnit(const LineMeasurementSetup& setup, const std::vector<std::complex<double>>& z,
                    std::uint64_t seed, bool noise = true);

}  // namespace eol::analysis
