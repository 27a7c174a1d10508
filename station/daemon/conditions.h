// Test conditions: what the station measures about the test itself, beside the motor.
//
//   clamp_pressure_bar             read at clamp confirmation; its window is the recipe's
//                                  fixture.clamp_pressure_bar (a safety interlock: the
//                                  watchdog stops the test outside it). The minimum and
//                                  maximum read from right before the relay closed through
//                                  the excitation are recorded as clamp_pressure_min_bar /
//                                  clamp_pressure_max_bar.
//   winding_temperature_c          estimated from the fitted winding resistance with copper's
//                                  temperature coefficient:
//                                    R = R_ref (1 + alpha (T - T_ref)),  alpha = 0.00393 1/K
//                                    =>  T = T_ref + (R / R_ref - 1) / alpha
//                                  R_ref and T_ref come from the recipe (the type's nominal
//                                  R at its reference temperature). The unit-to-unit spread of
//                                  R (2 % in the simulated population) reads as +-5 K.
//   excitation_v_rms, _a_rms       rms of the recorded voltage and current over the averaged
//                                  periods (the transient periods skipped): the level the
//                                  motor actually saw.
//
// Policy (recipe "conditions.out_of_window"): "error" ends a test whose condition is out of
// its window as ERROR "condition out of window: ..." (never PASS, never FAIL: the station did
// not measure under the conditions the limits assume); "record" only records them. No
// measurement is normalised: the temperature is estimated from R itself, so R normalised to
// T_ref would equal R_ref by construction and hide a wrong winding.
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "analysis/qc/measurement.h"
#include "analysis/signal/recording.h"
#include "db/test_conditions.h"

namespace eol::station {

inline constexpr double kCopperAlphaPerK = 0.00393;  // at 20 degC
// A winding temperature outside this range cannot be a winding's on a test station: the
// condition's reason then also names R and the recipe's reference (likely another motor's).
inline constexpr double kImplausibleWindingLoC = -20.0;
inline constexpr double kImplausibleWindingHiC = 120.0;

// The recipe's "conditions" section:
//   "conditions": {"winding_temperature_c": {"r_ref_ohm": 0.5, "t_ref_c": 20, "lo": 0, "hi": 45},
//                  "excitation_v_rms": {"lo": 1.2, "hi": 1.45},
//                  "excitation_a_rms": {"lo": 0.05, "hi": 2.0},
//                  "out_of_window": "error" | "record"}
// Every window is optional, and so is each of its bounds.
struct ConditionWindows {
  bool enabled = false;    // the recipe has the section
  double r_ref_ohm = 0.0;  // 0: no temperature estimate
  double t_ref_c = 20.0;
  analysis::Limit winding_temperature_c;
  analysis::Limit excitation_v_rms;
  analysis::Limit excitation_a_rms;
  bool error_when_out = true;  // "error"; false for "record"
};

double WindingTemperatureC(double r_ohm, double r_ref_ohm, double t_ref_c);
// Root mean square of x[skip..]; NaN when nothing is left.
double RmsAfter(const std::vector<double>& x, std::size_t skip);

// Sets excitation_v_rms, excitation_a_rms and (with r_ref_ohm and a finite r_ohm)
// winding_temperature_c of `conditions` (db/test_conditions.h), and conditions_in_window when
// the windows are enabled, and returns one line per condition outside its
// window: "winding temperature 61.3 degC outside 0.0..45.0 degC". Nothing is checked when the
// windows are not enabled. Without a recording (an FRF file judged offline) the excitation
// levels cannot be known: they are neither written nor checked, and the name of each such
// window the recipe sets is appended to `not_evaluated` ("excitation_v_rms", ...).
std::vector<std::string> EvaluateConditions(const ConditionWindows& windows,
                                            const analysis::Recording* recording,
                                            std::size_t transient_periods,
                                            std::optional<double> r_ohm,
                                            db::TestConditions& conditions,
                                            std::vector<std::string>* not_evaluated = nullptr);

}  // namespace eol::station
