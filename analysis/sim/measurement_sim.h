// A measured impedance through the project's simulator, for the gap benchmark and tests:
// the recipe's multisine (multisine.h) into any impedance Z(f), the periodic steady-state
// current (steady_state.h), white noise per sample on both channels as the simulated DAQ adds
// it (drivers/sim/sim_daq.h: 2 mV and 1 mA rms at 8 kHz), and the periodic errors-in-variables
// estimate with per-line sigma (periodic_frf.h).
//
// Expected per-line sigma of that estimate (analysis/README.md 3), for line amplitude |U_k| of the
// period (DFT scaled by 2/N), N samples per period, P averaged periods:
//   E|dU|^2 = 4 s_u^2 / N,  E|dI|^2 = 4 s_i^2 / N per period,  |I_k| = |U_k| / |Z_k|,
//   sigma_k^2 = |Z_k|^2 / P (E|dU|^2 / |U_k|^2 + E|dI|^2 / |I_k|^2).
#pragma once

#include <cstdint>
#include <vector>

#include "analysis/signal/multisine.h"
#include "analysis/signal/periodic_frf.h"
#include "analysis/sim/steady_state.h"

namespace eol::analysis {

struct SimulatedMeasurementOptions {
  std::size_t periods = 4;            // averaged
  std::size_t transient_periods = 1;  // played first and dropped
  double voltage_noise_v = 2.0e-3;    // rms per sample
  double current_noise_a = 1.0e-3;
  std::uint64_t seed = 1;

  bool IsValid(std::string* why) const;
};

// The recorded voltage and current (transient + averaged periods, noise added).
Recording SimulateImpedanceRecording(const ImpedanceFn& z, const Excitation& excitation,
                                     const SimulatedMeasurementOptions& options);

// The measured Frf (usable == false with the reason when the estimate fails).
FrfSummary SimulateImpedanceMeasurement(const ImpedanceFn& z, const Excitation& excitation,
                                        const SimulatedMeasurementOptions& options);

// sigma_k of the estimate at each excited line (see above).
std::vector<double> ExpectedLineSigma(const ImpedanceFn& z, const Excitation& excitation,
                                      const SimulatedMeasurementOptions& options);

}  // namespace eol::analysis
