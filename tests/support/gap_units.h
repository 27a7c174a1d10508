// Inputs for the gap diagnosis tests: the nominal motor network of the paper's shape and units
// measured through the simulator with unmodelled effects on top (tests/station/gap_cli_test.cc,
// the figure API and the engineer page tests).
#pragma once

#include <cstdint>
#include <vector>

#include "analysis/model/effects.h"
#include "analysis/sim/measurement_sim.h"

namespace eol::testing {

inline analysis::NominalNetwork GapNominal() {
  analysis::NominalNetwork n;
  n.motional = {0.5, 2e-3, 0.51, 390.0, 50.0};
  return n;
}

// The nominal's impedance on 200..800 Hz at 1 Hz, noise-free: a simulation.
inline analysis::Frf GapSimulation() {
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 1.0) f.push_back(x);
  return GapNominal().motional.Evaluate(f);
}

// Nominal + effects measured through the simulator (4 periods, DAQ noise).
inline analysis::Frf GapMeasured(const std::vector<analysis::AppliedEffect>& effects,
                                 std::uint64_t seed) {
  const analysis::NominalNetwork n = GapNominal();
  const analysis::Excitation ex = analysis::DesignMultisine(analysis::MultisineOptions{});
  analysis::SimulatedMeasurementOptions o;
  o.seed = seed;
  return analysis::SimulateImpedanceMeasurement(
             [&](double f) { return analysis::EvaluateNetwork(n, effects, f); }, ex, o)
      .frf;
}

}  // namespace eol::testing
