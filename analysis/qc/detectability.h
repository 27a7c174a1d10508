// Defect detectability in the real fixture (`eol detectability`).
//
// The model: the nominal rotor chain (rotor_chain.h) with the fixture stiffness of the real
// station (from the gap diagnosis' fixture_compliance, or given), R, L and T of the motor.
// For the good rotor and each defect class (one soft magnet, two, half, all; every bond at a
// fraction 0.1..0.9 of its stiffness) the expected measurement is Z on the recipe's lines with
// the per-line sigma of the recipe's excitation (line_measurement.h), and the station's fit
// (AnalyzeImpedance) on that noise-free curve predicts the measured values:
//   f0, Q, Rp, R, L as fitted; chi2/dof as 1 + chi2_0 / dof (chi2_0 of the noise-free fit: the
//   shape a single mode cannot follow, e.g. a soft magnet's local mode).
// Measurement sigma: the fit's standard errors at the expected curve (the Cramer-Rao bound of
// the recipe's excitation), and sqrt(2 / dof) for chi2/dof.
// Good-unit spread: per measurement, given (from a golden set or the recipe's limits); for
// chi2/dof the noise alone when not given. Separation of a class in a measurement:
//   sep = |x_defect - x_good| / sqrt(spread^2 + sigma^2),
// the recommended limit sits required_sigmas x that spread from the good value on the side of
// the defect, and miss = Phi((limit - x_defect) / spread) is the share of that class still
// passing it (spreads assumed equal for good and defective units).
// A class is separable when its best measurement reaches required_sigmas. Otherwise remedies
// with numbers: the fixture stiffness that separates it (searched up to 100 x, and rigid), the
// periods that would (noise-limited measurements only: sigma^2 ~ 1/P, chi2_0 ~ P), and the
// equivalent phase-pair coupling gain (Rp ~ T^2: a pair with r x the coupling acts as r^2 x
// the periods).
// Model POD against the defect size (MIL-HDBK-1823A's POD(a), here from the model rather than
// from hit/miss units): for "one_magnet" (one soft bond) and "all_magnets" (every bond soft)
// at each stiffness loss a of pod_losses (stiffness and damping of the good bond times 1 - a),
// POD(a) = 1 - miss of the best measurement at its recommended limit (the largest of the
// measurements' detection probabilities: a lower bound for the OR of all limits); a fit that
// finds no resonance is an ERROR, never a PASS: POD 1. a90 is the loss from which POD stays
// at or above 0.9 on the grid (interpolated): where POD dips again (one soft magnet whose own
// mode meets the rotor's near a loss of 0.98) a90 lies past the dip.
// a90/95 of the model: its one uncertain input is the good units' spread when it was estimated
// from spread_units golden units (0: given, e.g. from the recipe's limits: no a90/95). Every
// spread s is replaced by its one-sided upper confidence bound s sqrt(nu / chi2_nu(1 - gamma)),
// nu = spread_units - 1, gamma = pod_confidence; a wider spread puts the recommended limit
// further out and scatters the defect more, so POD falls: that curve is a lower confidence
// bound on POD(a) (pointwise, the model taken as right) and a90/95 is where it reaches 0.9 and
// stays, as a90 above. It says nothing about the model's own error: hit/miss units do
// (`eol production-bench`, `eol pod`). The model has no sampling
// error, so no a90/95: that needs units (hit/miss data from `eol production-bench` or `eol pod`).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"
#include "analysis/model/rotor_chain.h"
#include "analysis/signal/multisine.h"

namespace eol::analysis {

struct DetectabilityOptions {
  RotorChainParams rotor;  // nominal rotor with the real fixture (fixture must be set)
  double r_ohm = 0.5;
  double l_h = 2.0e-3;
  double transmission_nm_per_a = 0.05;
  MultisineOptions excitation;
  std::size_t periods = 4;
  std::size_t transient_periods = 1;
  double voltage_noise_v = 2.0e-3;
  double current_noise_a = 1.0e-3;
  ResonanceFitOptions fit;
  // Standard deviation of good units per measurement name; measurements without one are not
  // judged (chi2/dof always is, with its noise spread when absent).
  std::map<std::string, double> unit_spread;
  std::vector<double> bond_fractions = {0.1, 0.3, 0.5, 0.7, 0.9};
  double required_sigmas = 3.0;
  std::vector<double> pod_losses = {0.2,  0.4,  0.6,  0.7,  0.8,  0.85, 0.9,
                                    0.92, 0.94, 0.95, 0.96, 0.97, 0.98, 0.99};
  int spread_units = 0;  // golden units unit_spread was estimated from (0: not a sample)
  double pod_confidence = 0.95;

  bool IsValid(std::string* why) const;
};

struct MeasurementSeparation {
  std::string name;
  double good = 0.0;
  double defect = 0.0;
  double sigma = 0.0;   // measurement
  double spread = 0.0;  // good units (as given)
  double separation = 0.0;
  double recommended_limit = 0.0;  // lo when the defect lies below, else hi
  bool limit_is_lo = true;
  double miss_probability = 0.0;
};

struct DefectPrediction {
  std::string defect;  // one_soft_magnet, two_soft_magnets, half_soft, all_soft, weak_bonds:0.5
  bool fit_usable = false;
  std::string fit_message;
  double f0_hz = 0.0, q = 0.0, rp_ohm = 0.0, chi2_per_dof = 0.0;
  double curve_separation = 0.0;  // sqrt(sum 2 |Z_d - Z_g|^2 / sigma^2): noise only
  std::vector<MeasurementSeparation> measurements;
  std::string best;  // measurement with the largest separation
  double best_separation = 0.0;
  bool separable = false;
  std::vector<std::string> remedies;
};

struct ModelPodPoint {
  double loss = 0.0;  // a
  double pod = 0.0;
  double pod_lower = 0.0;  // with the spread at its upper bound (NaN without spread_units)
  double f0_hz = 0.0;      // predicted fitted f0 (0 when the fit finds none)
  std::string best;        // measurement that gives the POD
};

struct ModelPod {
  std::string name;  // "one_magnet", "all_magnets"
  std::vector<ModelPodPoint> points;
  double a90 = 0.0;     // NaN when POD ends below 0.9 on the grid
  double a90_95 = 0.0;  // the same on pod_lower; NaN without spread_units or when not reached
};

struct DetectabilitySummary {
  bool usable = false;
  std::string message;
  double k_fixture_nm_per_rad = 0.0;
  double f0_good_hz = 0.0, q_good = 0.0, chi2_good = 0.0;
  int dof = 0;
  std::vector<DefectPrediction> classes;
  std::vector<ModelPod> pod;
};

DetectabilitySummary PredictDetectability(const DetectabilityOptions& options);

}  // namespace eol::analysis
