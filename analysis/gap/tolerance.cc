#include "analysis/gap/tolerance.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>

namespace eol::analysis {

bool NominalTolerances::IsValid(std::string* why) const {
  const double percent[] = {r, l, torque_constant, inertia, stiffness, daq_gain};
  for (int i = 0; i < 6; ++i) {
    if (!(percent[i] > 0.0 && percent[i] <= 2.0 && std::isfinite(percent[i]))) {
      if (why)
        *why = std::string("tolerance ") + kToleranceNames[i == 5 ? 6 : i] +
               " must be in (0, 2] (a relative sd)";
      return false;
    }
  }
  if (!(damping_factor > 1.0 && damping_factor <= 1000.0)) {
    if (why) *why = "tolerance damping must be a factor in (1, 1000]";
    return false;
  }
  return true;
}

std::vector<double> NominalTolerances::Sd() const {
  return {r, l, torque_constant, inertia, stiffness, std::log(damping_factor), daq_gain};
}

bool NominalTolerances::Set(const std::string& name, double value) {
  double* field[] = {&r, &l, &torque_constant, &inertia, &stiffness, &damping_factor, &daq_gain};
  for (int i = 0; i < kToleranceCount; ++i)
    if (name == kToleranceNames[i]) {
      *field[i] = value;
      return true;
    }
  return false;
}

bool ParseTolerances(const std::string& text, NominalTolerances* t, std::string* why) {
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    const auto eq = item.find('=');
    const std::string name = item.substr(0, eq);
    const std::string value = eq == std::string::npos ? "" : item.substr(eq + 1);
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (eq == std::string::npos || value.empty() || *end != '\0') {
      *why = "'" + item + "': want name=value";
      return false;
    }
    if (!t->Set(name, v)) {
      *why = "unknown tolerance '" + name +
             "' (known: r, l, torque_constant, inertia, stiffness, damping, daq_gain)";
      return false;
    }
  }
  return t->IsValid(why);
}

TolerancePrior::TolerancePrior(Quantity quantity, const NominalTolerances& t, double widen) {
  const std::vector<double> sd = t.Sd();
  sd_ = Eigen::Map<const Eigen::VectorXd>(sd.data(), kToleranceCount) * widen;
  // Columns: R, L, T, J, k, c, G (tolerance.h).
  if (quantity == Quantity::kMobility) {
    map_.resize(2, kToleranceCount);
    map_ << 0, 0, 1, -1, 0, 0, 1,  // ln g = dT - dJ + dG
        0, 0, 0, -1, 0, 1, 0;      // ln a = dc - dJ
  } else {
    map_.resize(5, kToleranceCount);
    map_ << 1, 0, 0, 0, 0, 0, 1,   // ln R
        0, 1, 0, 0, 0, 0, 1,       // ln L
        0, 0, 2, 0, 0, -1, 1,      // ln Rp
        0, 0, 0, -0.5, 0.5, 0, 0,  // ln f0
        0, 0, 0, 0.5, 0.5, -1, 0;  // ln Q
  }
  const Eigen::MatrixXd s2 = sd_.array().square().matrix().asDiagonal();
  const Eigen::MatrixXd c = map_ * s2 * map_.transpose();
  const Eigen::LLT<Eigen::MatrixXd> llt(c);
  const Eigen::MatrixXd lower = llt.matrixL();
  // W = L^-1: W^T W = (L L^T)^-1 = C^-1.
  whiten_ =
      lower.triangularView<Eigen::Lower>().solve(Eigen::MatrixXd::Identity(c.rows(), c.cols()));
  lower_ = lower;
  gain_ = s2 * map_.transpose() * llt.solve(Eigen::MatrixXd::Identity(c.rows(), c.cols()));
}

Eigen::VectorXd TolerancePrior::Whitened(const Eigen::VectorXd& u) const {
  return u / std::sqrt(1.0 + u.squaredNorm() / (kMaxTolerances * kMaxTolerances));
}

Eigen::VectorXd TolerancePrior::Coordinates(const Eigen::VectorXd& d) const {
  Eigen::VectorXd z = whiten_ * d;
  const double r = z.norm();
  if (r >= 0.99 * kMaxTolerances) z *= 0.99 * kMaxTolerances / r;
  return z / std::sqrt(1.0 - z.squaredNorm() / (kMaxTolerances * kMaxTolerances));
}

std::vector<ToleranceDeviation> TolerancePrior::Physical(const Eigen::VectorXd& d) const {
  const Eigen::VectorXd delta = gain_ * d;
  std::vector<ToleranceDeviation> out;
  for (int i = 0; i < kToleranceCount; ++i)
    out.push_back({kToleranceNames[i], std::expm1(delta(i)), delta(i) / sd_(i)});
  return out;
}

}  // namespace eol::analysis
