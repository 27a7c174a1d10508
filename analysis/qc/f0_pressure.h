// The resonance at the reference clamp pressure: f0 with the clamp's share of its spread taken
// out, from the pressure the station reads at clamp confirmation anyway.
//
//   resonance_f_ref_pressure_hz = f0 (p_ref / p)^m                       (Hz, one-sided lo)
//
// Physics: the fixture's torsional spring is a friction clamp whose contact stiffness grows with
// the clamping force (Hertz: k ~ F^(1/3)); the first mode's f0 ~ sqrt(k_eff / J) with the
// fixture a large share s of the chain's compliance, so d ln f0 / d ln p = s / 6 (about 0.11
// for s = 2/3). The pressure regulator's spread from part to part therefore spreads f0 among
// good rotors, and a soft bond has to lower f0 past that spread to be caught. The exponent m is
// measured, not assumed: teaching regresses ln f0 on ln p over the golden units and declares
// the measurement only when the slope is positive and significant (TeachF0Pressure).
// Evidence (analysis/qc/README.md): on tests/peers/independent_population.py's chain (600
// good rotors, seed 5), slope 0.114, the good units' f0 spread 1.06 % -> 0.85 %, all ten bonds
// at a loss of 0.92 from z -2.56 to -3.20.
//
// The station computes it in the one judge (station/daemon/judge.h) from
// conditions.clamp_pressure_bar; `eol analyze --clamp-pressure-bar P` gives the pressure for a file
// judged offline. Without a pressure the measurement is missing, and a declared limit on it makes
// the verdict ERROR, never PASS. Its sigma is f0's scaled (the pressure reading's own error is
// neglected: a 0.01 bar resolution moves f0 by 2e-4 relative at m = 0.11, far below the good units'
// spread).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "analysis/qc/measurement.h"

namespace eol::analysis {

struct F0PressureDefinition {
  double exponent = 0.0;          // m, in (0, 0.5]: f0 ~ sqrt(k) and k at most ~ p
  double pressure_ref_bar = 0.0;  // geometric mean of the golden units' clamp pressure

  bool IsValid(std::string* why) const;
  bool operator==(const F0PressureDefinition&) const = default;
};

// The measurement of one unit from its resonance_f_hz and the clamp pressure (bar); nullopt
// when either is missing or not positive and finite.
std::optional<Estimate> F0AtRefPressure(const std::map<std::string, Estimate>& values,
                                        std::optional<double> clamp_pressure_bar,
                                        const F0PressureDefinition& definition);

// Adds resonance_f_ref_pressure_hz to `values` when F0AtRefPressure gives one (else leaves them
// unchanged).
void AddF0AtRefPressure(std::map<std::string, Estimate>& values,
                        std::optional<double> clamp_pressure_bar,
                        const F0PressureDefinition& definition);

// Least squares of ln f0 on ln p over the golden units: the slope, its standard error and t,
// and the spread of ln f0 (percent, n - 1) before and of the residual (n - 2) after.
struct F0PressureFit {
  int units = 0;
  double slope = 0.0, slope_sigma = 0.0, t = 0.0;
  double spread_before_pct = 0.0, spread_after_pct = 0.0;
  std::optional<F0PressureDefinition> definition;  // set when used (below)
  std::string note;                                // what was found and why it is (not) used
};

// The slope's t at which the normalisation is declared: about a 0.1 % chance that a fixture
// whose f0 does not follow the pressure shows a slope this significant by chance.
inline constexpr double kF0PressureMinT = 3.0;

// From (f0 Hz, clamp pressure bar) of good units. Used (definition set) when there are at
// least 3 units, the pressure varies, and the slope is positive, at most 0.5 and its t at
// least kF0PressureMinT. Throws std::invalid_argument when a value is not positive and finite.
F0PressureFit TeachF0Pressure(const std::vector<std::pair<double, double>>& f0_and_pressure);

}  // namespace eol::analysis
