#include "analysis/model/torsional_chain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

// Adds the element's coefficient v between its ends to m.
void Stamp(const TorsionalElement& e, double v, Eigen::MatrixXd* m) {
  (*m)(e.a, e.a) += v;
  if (e.b == kGround) return;
  (*m)(e.b, e.b) += v;
  (*m)(e.a, e.b) -= v;
  (*m)(e.b, e.a) -= v;
}

}  // namespace

double ChainMode::RpOhm(double transmission_nm_per_a) const {
  const double w = 2.0 * std::numbers::pi * f_hz;
  const double c = w / q;
  return transmission_nm_per_a * transmission_nm_per_a * participation / c;
}

int TorsionalChain::AddInertia(std::string name, double inertia_kg_m2) {
  names_.push_back(std::move(name));
  inertia_.push_back(inertia_kg_m2);
  weight_.push_back(0.0);
  return size() - 1;
}

void TorsionalChain::AddElement(std::string name, int a, int b, double stiffness_nm_per_rad,
                                double damping_nms_per_rad) {
  elements_.push_back({std::move(name), a, b, stiffness_nm_per_rad, damping_nms_per_rad});
}

void TorsionalChain::SetTorqueWeight(int inertia, double weight) {
  if (inertia < 0 || inertia >= size())
    throw std::out_of_range("SetTorqueWeight: no inertia " + std::to_string(inertia));
  weight_[static_cast<std::size_t>(inertia)] = weight;
}

bool TorsionalChain::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (inertia_.empty()) return fail("the chain has no inertia");
  for (int i = 0; i < size(); ++i)
    if (!(std::isfinite(inertia_[static_cast<std::size_t>(i)]) &&
          inertia_[static_cast<std::size_t>(i)] > 0.0))
      return fail("inertia '" + names_[static_cast<std::size_t>(i)] +
                  "' must be finite and positive");
  for (const TorsionalElement& e : elements_) {
    if (e.a < 0 || e.a >= size() || e.b < kGround || e.b >= size() || e.a == e.b)
      return fail("element '" + e.name + "' joins invalid inertias");
    if (!(std::isfinite(e.stiffness_nm_per_rad) && e.stiffness_nm_per_rad > 0.0))
      return fail("element '" + e.name + "': stiffness must be finite and positive");
    if (!(std::isfinite(e.damping_nms_per_rad) && e.damping_nms_per_rad >= 0.0))
      return fail("element '" + e.name + "': damping must be finite and not negative");
  }
  bool driven = false;
  for (double w : weight_) {
    if (!std::isfinite(w)) return fail("torque weights must be finite");
    driven = driven || w != 0.0;
  }
  if (!driven) return fail("no inertia takes the electromagnetic torque");
  const Eigen::LLT<Eigen::MatrixXd> llt(StiffnessMatrix());
  if (llt.info() != Eigen::Success)
    return fail("the stiffness matrix is singular: some inertia is not held to ground");
  return true;
}

Eigen::MatrixXd TorsionalChain::MassMatrix() const {
  Eigen::VectorXd j(size());
  for (int i = 0; i < size(); ++i) j[i] = inertia_[static_cast<std::size_t>(i)];
  return j.asDiagonal();
}

Eigen::MatrixXd TorsionalChain::StiffnessMatrix() const {
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(size(), size());
  for (const TorsionalElement& e : elements_) Stamp(e, e.stiffness_nm_per_rad, &k);
  return k;
}

Eigen::MatrixXd TorsionalChain::DampingMatrix() const {
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(size(), size());
  for (const TorsionalElement& e : elements_) Stamp(e, e.damping_nms_per_rad, &c);
  return c;
}

Eigen::VectorXd TorsionalChain::TorqueWeights() const {
  Eigen::VectorXd b(size());
  for (int i = 0; i < size(); ++i) b[i] = weight_[static_cast<std::size_t>(i)];
  return b;
}

Cplx TorsionalChain::Mobility(double f_hz) const {
  const Cplx s(0.0, 2.0 * std::numbers::pi * f_hz);
  const Eigen::MatrixXcd d = (s * s) * MassMatrix().cast<Cplx>() +
                             s * DampingMatrix().cast<Cplx>() + StiffnessMatrix().cast<Cplx>();
  const Eigen::VectorXcd b = TorqueWeights().cast<Cplx>();
  const Eigen::VectorXcd x = d.partialPivLu().solve(b);
  return s * b.dot(x);  // b is real: dot's conjugation of b changes nothing
}

std::vector<ChainMode> TorsionalChain::Modes() const {
  const Eigen::MatrixXd m = MassMatrix();
  const Eigen::MatrixXd c = DampingMatrix();
  const Eigen::VectorXd b = TorqueWeights();
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> eig(StiffnessMatrix(), m);
  if (eig.info() != Eigen::Success) throw std::runtime_error("chain modes: eigensolver failed");
  std::vector<ChainMode> modes;
  for (int n = 0; n < size(); ++n) {
    ChainMode mode;
    Eigen::VectorXd phi = eig.eigenvectors().col(n);
    phi /= std::sqrt(phi.dot(m * phi));
    const double w = std::sqrt(std::max(eig.eigenvalues()[n], 0.0));
    mode.f_hz = w / (2.0 * std::numbers::pi);
    const double cn = phi.dot(c * phi);
    mode.q = cn > 0.0 ? w / cn : std::numeric_limits<double>::infinity();
    mode.participation = std::pow(phi.dot(b), 2);
    mode.shape = std::move(phi);
    modes.push_back(std::move(mode));
  }
  return modes;
}

Cplx ClampedMotor::Impedance(double f_hz) const {
  const Cplx s(0.0, 2.0 * std::numbers::pi * f_hz);
  return r_ohm + s * l_h + transmission_nm_per_a * transmission_nm_per_a * chain.Mobility(f_hz);
}

Frf ClampedMotor::Evaluate(const std::vector<double>& freq_hz) const {
  Frf z;
  z.freq_hz = freq_hz;
  z.value.reserve(freq_hz.size());
  for (double f : freq_hz) z.value.push_back(Impedance(f));
  z.quantity = Quantity::kImpedanceOhm;
  z.method = "model";
  return z;
}

std::vector<MotionalImpedance> ClampedMotor::ModalTerms() const {
  std::vector<MotionalImpedance> terms;
  for (const ChainMode& mode : chain.Modes()) {
    MotionalImpedance m;
    m.r_ohm = r_ohm;
    m.l_h = l_h;
    m.rp_ohm = mode.RpOhm(transmission_nm_per_a);
    m.f0_hz = mode.f_hz;
    m.q = mode.q;
    terms.push_back(m);
  }
  return terms;
}

TorsionalChain SingleModeChain(const ClampedRotor& rotor) {
  TorsionalChain chain;
  const int j = chain.AddInertia("rotor", rotor.inertia_kg_m2);
  chain.AddElement("rotor+fixture", j, kGround, rotor.EffectiveStiffnessNmPerRad(),
                   rotor.DampingNmsPerRad());
  chain.SetTorqueWeight(j, 1.0);
  return chain;
}

}  // namespace eol::analysis
