// Channel calibration measured with a reference resistor in place of the motor.
//
// With a resistor R_ref between the terminals the true impedance is R_ref at every line. The
// measured one carries the acquisition's errors: a gain g (the ratio of the voltage divider to
// the current shunt is off by g) and a skew tau of the current channel behind the voltage
// channel (drivers::Calibration::channel_delay_s has the same sign), i(t) read as i(t - tau):
//   Z_meas(f) = R_ref g exp(+j w tau),   w = 2 pi f
// (analysis/model/effects.h writes the same skew as exp(-s tau_e): tau_e = -tau.)
// With y_k = ln(Z_k / R_ref) = ln g + j w_k tau + e_k, and E|dZ_k|^2 = sigma_k^2, the real and
// imaginary parts of e_k each have variance v_k = sigma_k^2 / (2 |Z_k|^2), so both are weighted
// linear least squares with weights 1/v_k:
//   ln g = sum(Re y_k / v_k) / sum(1 / v_k),        var = 1 / sum(1 / v_k)
//   tau  = sum(w_k phi_k / v_k) / sum(w_k^2 / v_k),  var = 1 / sum(w_k^2 / v_k)
// with phi_k = arg Z_k unwrapped along frequency. Each variance is scaled by chi2/dof of its
// own residuals when that exceeds 1 (the data scatter more than sigma says), and by it alone
// when the FRF has no sigma (unit weights). sigma(g) = g sigma(ln g).
// The corrected calibration: shunt_ohm' = shunt_ohm / g (Z is proportional to the shunt value
// used in the conversion), channel_delay_s' = channel_delay_s + tau.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/signal/periodic_frf.h"
#include "analysis/signal/recording.h"

namespace eol::analysis {

struct ReferenceCalibrationOptions {
  double reference_ohm = 0.0;  // R_ref, the resistor's known value
  // A gain outside [1/max_gain_error, max_gain_error] means a wrong R_ref or wiring, not a
  // calibration: not usable.
  double max_gain_error = 2.0;
  PeriodicFrfOptions frf;  // for the recording form

  bool IsValid(std::string* why) const;
};

struct ReferenceCalibrationSummary {
  bool usable = false;
  std::string message;
  double gain = 0.0;  // g, measured / true
  double gain_sigma = 0.0;
  double delay_s = 0.0;  // tau, current channel behind voltage channel
  double delay_sigma_s = 0.0;
  double magnitude_chi2_per_dof = 0.0;
  double phase_chi2_per_dof = 0.0;
  std::size_t lines = 0;
  Frf z;  // the measured impedance the fit used
};

// x(t - delay_s) of a periodic signal whose period is all of x (a fractional delay, exact for
// a band-limited periodic signal): X_k exp(-j 2 pi k delay_s fs / N), the Nyquist bin kept
// real. A negative delay advances. Used to inject and to compensate a channel skew.
void DelayPeriodic(std::vector<double>& x, double delay_s, double sample_rate_hz);

// Never throws for bad data: usable == false with the reason.
ReferenceCalibrationSummary EstimateReferenceCalibration(
    const Frf& z, const ReferenceCalibrationOptions& options);
// EstimatePeriodicFrf of the recording (excited `lines` of one period), then the fit above.
ReferenceCalibrationSummary EstimateReferenceCalibration(
    const Recording& recording, const std::vector<std::size_t>& lines,
    const ReferenceCalibrationOptions& options);

}  // namespace eol::analysis
