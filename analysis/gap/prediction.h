// Carrying a diagnosed gap over to another simulation: "this real fixture, that rotor".
//
// The effects fitted against simulation 1 are applied to the nominal of simulation 2 (the
// same test set-up, another design or defect). Parameters relative to the nominal are
// re-expressed so that the physical quantity stays:
//   fixture_compliance  the fixture's stiffness stays: kappa_2 = kappa_1 k_1 / k_2 with
//                       k_i = J_i w0_i^2 (with either J unknown, both are taken equal:
//                       kappa_2 = kappa_1 (f0_1 / f0_2)^2); its loss factor stays;
//   every other effect  its parameters stay (skin_effect is relative to R by definition).
// For an impedance the predicted FRF's resonance is fitted (resonance_fit.h) to give where the
// second design rings in the real set-up; its uncertainty is propagated to first order from
// the fitted parameters' standard deviations (each moved by one sigma, correlations
// neglected).
#pragma once

#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/gap/diagnosis.h"
#include "analysis/model/effects.h"

namespace eol::analysis {

struct PredictionSummary {
  bool usable = false;
  std::string message;
  std::vector<AppliedEffect> effects;  // as applied to the second nominal
  Frf predicted;                       // nominal 2 + effects on freq_hz, noise-free
  double f0_simulated_hz = 0.0;        // nominal 2's resonance (impedance)
  double f0_predicted_hz = 0.0;        // where it rings in the real set-up
  double sigma_f0_hz = 0.0;
  double q_predicted = 0.0;
};

// `fitted` is the winning entry of a diagnosis against nominal_1 (its params give the
// sigmas); an empty winner predicts the second nominal unchanged.
PredictionSummary PredictWithEffects(const NominalNetwork& nominal_1, const RankedEffect& fitted,
                                     const NominalNetwork& nominal_2,
                                     const std::vector<double>& freq_hz);

}  // namespace eol::analysis
