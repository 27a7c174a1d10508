// A lumped torsional network: inertias joined by springs with dampers (analysis/README.md 2).
//
// Degrees of freedom theta (rad), one per inertia. Each element joins two inertias, or one
// inertia and ground, with a spring k (N m/rad) in parallel with a damper c (N m s/rad).
// The electromagnetic torque tau = T i acts on the inertias with weights b (the share of the
// torque each one takes; for the rotor, 1/N on each of N magnets and 0 elsewhere):
//   M theta'' + C theta' + K theta = b tau(t)
// with M = diag(J), and K, C assembled from the elements (k on the diagonal of both ends,
// -k off the diagonal between them; a grounded element adds k to one diagonal entry only).
// By reciprocity the back-EMF is u = T b^T theta', so the motional impedance seen at the
// winding is
//   Z_mot(s) = T^2 Y_b(s),   Y_b(s) = s b^T (s^2 M + s C + K)^-1 b   (rad/s per N m),
// Y_b being the angular velocity of the driven DOFs (weighted by b) per unit torque. For one
// inertia J on a spring k with damper c this is T^2 / (s J + c + k/s) = T^2 / Z_m(s) (eq. 12-13).
#pragma once

#include <Eigen/Dense>
#include <complex>
#include <string>
#include <vector>

#include "analysis/model/motor_model.h"

namespace eol::analysis {

inline constexpr int kGround = -1;

struct TorsionalElement {
  std::string name;
  int a = kGround;  // inertia index
  int b = kGround;  // inertia index, or kGround
  double stiffness_nm_per_rad = 0.0;
  double damping_nms_per_rad = 0.0;
};

// One undamped mode of K phi = w^2 M phi, phi normalised to phi^T M phi = 1. Its damping and
// electrical visibility use the proportional-damping approximation (off-diagonal phi_m^T C
// phi_n neglected, good for lightly damped, well separated modes):
//   c_n = phi^T C phi (1/s),  Q_n = w_n / c_n,  g_n = (phi^T b)^2 (1/(kg m^2)),
// and the mode contributes T^2 g_n s / (s^2 + c_n s + w_n^2) to Z: a parallel R-L-C with
//   Rp_n = T^2 g_n / c_n,  f0 = w_n / (2 pi),  Q = Q_n   (motor_model.h).
// The modal inertia seen by the torque is 1 / g_n (J_r of the paper for this mode).
struct ChainMode {
  double f_hz = 0.0;
  double q = 0.0;
  double participation = 0.0;  // g_n = (phi^T b)^2, 1/(kg m^2)
  Eigen::VectorXd shape;       // phi, mass-normalised
  // Rp_n for transmission T (N m/A): T^2 g_n / c_n (ohm).
  double RpOhm(double transmission_nm_per_a) const;
};

class TorsionalChain {
 public:
  // Returns the index of the new inertia.
  int AddInertia(std::string name, double inertia_kg_m2);
  // b = kGround joins inertia a to ground.
  void AddElement(std::string name, int a, int b, double stiffness_nm_per_rad,
                  double damping_nms_per_rad);
  void SetTorqueWeight(int inertia, double weight);

  int size() const { return static_cast<int>(inertia_.size()); }
  const std::vector<std::string>& names() const { return names_; }
  const std::vector<TorsionalElement>& elements() const { return elements_; }

  // False with the reason in *why unless: at least one inertia, every inertia positive,
  // every element joins valid indices with k > 0 and c >= 0, some torque weight non-zero,
  // and K is positive definite (every inertia is held to ground through springs).
  bool IsValid(std::string* why) const;

  Eigen::MatrixXd MassMatrix() const;
  Eigen::MatrixXd StiffnessMatrix() const;
  Eigen::MatrixXd DampingMatrix() const;
  Eigen::VectorXd TorqueWeights() const;

  // Y_b(j 2 pi f) (rad/s per N m), f > 0.
  std::complex<double> Mobility(double f_hz) const;
  // Undamped modes, ascending in frequency (requires IsValid).
  std::vector<ChainMode> Modes() const;

 private:
  std::vector<std::string> names_;
  std::vector<double> inertia_;
  std::vector<double> weight_;
  std::vector<TorsionalElement> elements_;
};

// The clamped motor: winding R and L, transducer T at the clamped rotor position, and the
// rotor chain. Z(s) = R + s L + T^2 Y_b(s).
struct ClampedMotor {
  double r_ohm = 0.0;
  double l_h = 0.0;
  double transmission_nm_per_a = 0.0;
  TorsionalChain chain;

  std::complex<double> Impedance(double f_hz) const;
  Frf Evaluate(const std::vector<double>& freq_hz) const;  // method "model", no sigma
  // Each mode as R + sL + parallel R-L-C (R and L on every term), ascending in frequency.
  std::vector<MotionalImpedance> ModalTerms() const;
};

// A single-mode chain with the same impedance as the ClampedRotor: one inertia J on the
// series spring k_eff (rotor and fixture, massless junction) with damper R_m, torque weight 1.
TorsionalChain SingleModeChain(const ClampedRotor& rotor);

}  // namespace eol::analysis
