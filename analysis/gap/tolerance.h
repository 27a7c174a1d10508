// The design's tolerances as the prior of the nominal's calibration (issue 38): a unit is never
// its simulation. Every parameter of the design is off by up to its tolerance and the DAQ has a
// gain error, so the gap diagnosis (diagnosis.h) refits the nominal's own parameters in every
// fit (none, each effect, each pair) under a Gaussian prior of these tolerances, and names an
// effect only where that calibration cannot reach the data.
//
// Physical parameters, each as delta = ln(value / design value) with a Gaussian prior of
// standard deviation sd (one tolerance = one sd):
//   R (winding resistance) 10 %, L (inductance) 8 %, T (torque constant) 6 %, J (rotor
//   inertia) 6 %, k (support stiffness) 15 %, c (damping) x3 (log-normal: sd = ln 3),
//   G (the DAQ's gain: the measured H is G times the unit's) 1 %.
// Only combinations of them are identifiable (effects.h): for an impedance the nominal's
//   ln R' = dR + dG,  ln L' = dL + dG,  ln Rp' = 2 dT - dc + dG,
//   ln f0' = (dk - dJ) / 2,  ln Q' = (dk + dJ) / 2 - dc          (Rp = T^2 / c,
//   w0 = sqrt(k / J), Q = sqrt(k J) / c), and for a mobility M = G T / (J s + c):
//   ln g' = dT - dJ + dG,  ln a' = dc - dJ.
// With d = M delta the identifiable shifts, the prior on d is Gaussian with covariance
// C = M S^2 M^T (S = diag(sd)): the seven physical offsets integrate out exactly to it. The
// fits take d as the nominal's parameters and add the rows W d (W^T W = C^-1) to the residual:
// the prior's -2 ln p, d^T C^-1 d, joins the cost. The physical offsets the calibration implies
// are the most probable ones given d: delta = S^2 M^T C^-1 d (Physical), each reported in
// tolerances (delta / sd).
// Within the tolerances means within them: the calibration's prior is truncated at a
// Mahalanobis radius of kMaxTolerances (|W d| < 4: a design whose every parameter is off by a
// tolerance or two lies well inside; a 5-dimensional Gaussian leaves about 1 % outside), by the
// fits' coordinates (Coordinates), so the calibration cannot re-draw a structure (a fixture
// spring's f0 at 7 tolerances): that calibration is the finding beyond the tolerances
// (diagnosis.h), not "none".
#pragma once

#include <Eigen/Dense>
#include <string>
#include <vector>

#include "analysis/frf.h"

namespace eol::analysis {

// One sd of each parameter's relative offset (damping: the factor whose ln is one sd).
struct NominalTolerances {
  double r = 0.10;
  double l = 0.08;
  double torque_constant = 0.06;
  double inertia = 0.06;
  double stiffness = 0.15;
  double damping_factor = 3.0;  // log-normal: sd of ln c = ln 3
  double daq_gain = 0.01;

  bool IsValid(std::string* why) const;
  // sd of ln(value) for R, L, T, J, k, c, G (kToleranceNames order).
  std::vector<double> Sd() const;
  // Sets one tolerance by its stable name (kToleranceNames); false for an unknown name.
  bool Set(const std::string& name, double value);
};

// The stable names (JSON, CLI, reports), in the order of NominalTolerances::Sd.
inline constexpr const char* kToleranceNames[] = {
    "r", "l", "torque_constant", "inertia", "stiffness", "damping", "daq_gain"};
inline constexpr int kToleranceCount = 7;

// Parses "name=value,name=value" (kToleranceNames; damping is the factor, e.g. 3) over the
// defaults in *t. Returns false with the cause in *why (unknown name, bad number).
bool ParseTolerances(const std::string& text, NominalTolerances* t, std::string* why);

// One physical parameter's offset as the calibration implies it.
struct ToleranceDeviation {
  std::string name;         // kToleranceNames
  double offset = 0.0;      // relative: exp(delta) - 1
  double tolerances = 0.0;  // delta / sd
};

inline constexpr double kMaxTolerances = 4.0;

class TolerancePrior {
 public:
  // The prior on the identifiable log-shifts of the quantity's nominal (impedance: ln R, ln L,
  // ln Rp, ln f0, ln Q; mobility: ln g, ln a), each sd times `widen`.
  TolerancePrior(Quantity quantity, const NominalTolerances& t, double widen = 1.0);

  // The identifiable shifts (the size of d).
  int size() const { return static_cast<int>(map_.rows()); }
  // The fits' coordinates u for the shifts (below): z = W d = u / sqrt(1 + |u|^2 / K^2), so
  // |W d| < K = kMaxTolerances for every u, z ~ u inside; the prior's rows are z (their squared
  // norm d^T C^-1 d), and its Occam term ln det(I + C A) = ln det(I + A_u) = ln det(H_uu) at
  // the optimum (A_u the information in u: z ~ u there).
  Eigen::VectorXd Shift(const Eigen::VectorXd& u) const { return lower_ * Whitened(u); }
  Eigen::VectorXd Whitened(const Eigen::VectorXd& u) const;
  // u for a shift d (one outside the radius is pulled to 0.99 K along its direction).
  Eigen::VectorXd Coordinates(const Eigen::VectorXd& d) const;
  // d^T C^-1 d.
  double Penalty(const Eigen::VectorXd& d) const { return (whiten_ * d).squaredNorm(); }
  // The most probable physical offsets given d, in kToleranceNames order.
  std::vector<ToleranceDeviation> Physical(const Eigen::VectorXd& d) const;

 private:
  Eigen::MatrixXd map_;     // d = M delta
  Eigen::VectorXd sd_;      // of delta
  Eigen::MatrixXd gain_;    // S^2 M^T C^-1
  Eigen::MatrixXd whiten_;  // W, W^T W = C^-1
  Eigen::MatrixXd lower_;   // W^-1 (C = L L^T)
};

}  // namespace eol::analysis
