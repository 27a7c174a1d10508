#include "analysis/sim/time_domain.h"

#include <cmath>
#include <random>
#include <stdexcept>
// Eigen 3.4's matrix exponential trips GCC 12's -Wuse-after-free (a false positive inside
// Eigen's temporaries); keep it quiet for this header only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuse-after-free"
#include <unsupported/Eigen/MatrixFunctions>
#pragma GCC diagnostic pop

namespace eol::analysis {
namespace {

// Monomial coefficients (rows j = power 0..P-1, columns q = node) of the Lagrange basis
// polynomials through the nodes first, first + 1, ..., first + P - 1.
Eigen::MatrixXd LagrangeMonomials(int first, int points) {
  Eigen::MatrixXd coef = Eigen::MatrixXd::Zero(points, points);
  for (int q = 0; q < points; ++q) {
    Eigen::VectorXd poly = Eigen::VectorXd::Zero(points);
    poly[0] = 1.0;
    double denom = 1.0;
    int degree = 0;
    for (int m = 0; m < points; ++m) {
      if (m == q) continue;
      const double tm = first + m;
      for (int k = degree + 1; k >= 1; --k) poly[k] = poly[k - 1] - tm * poly[k];
      poly[0] = -tm * poly[0];
      ++degree;
      denom *= static_cast<double>(q - m);
    }
    coef.col(q) = poly / denom;
  }
  return coef;
}

}  // namespace

bool TimeDomainOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(std::isfinite(sample_rate_hz) && sample_rate_hz > 0.0))
    return fail("sample_rate_hz must be finite and positive");
  if (!(circuit.amplifier_output_ohm >= 0.0 && circuit.shunt_ohm >= 0.0 &&
        std::isfinite(circuit.SeriesOhm())))
    return fail("amplifier_output_ohm and shunt_ohm must be finite and not negative");
  if (hold == InputHold::kBandLimited &&
      !(hold_points >= 2 && hold_points <= 32 && hold_points % 2 == 0))
    return fail("hold_points must be even and in [2, 32]");
  return true;
}

StateSpace ClampedMotorStateSpace(const ClampedMotor& motor, const BenchCircuit& circuit) {
  std::string why;
  if (!motor.chain.IsValid(&why)) throw std::invalid_argument("clamped motor: " + why);
  const double r_total = motor.r_ohm + circuit.SeriesOhm();
  if (!(r_total > 0.0 && motor.l_h > 0.0 && std::isfinite(motor.transmission_nm_per_a)))
    throw std::invalid_argument("clamped motor: R + R_out + R_sh and L must be positive, T finite");
  const int n = motor.chain.size();
  const int nx = 2 * n + 1;
  const int cur = 2 * n;
  const Eigen::VectorXd inv_j = motor.chain.MassMatrix().diagonal().cwiseInverse();
  const Eigen::VectorXd bt = motor.chain.TorqueWeights() * motor.transmission_nm_per_a;
  StateSpace ss;
  ss.a = Eigen::MatrixXd::Zero(nx, nx);
  ss.a.block(0, n, n, n).setIdentity();
  ss.a.block(n, 0, n, n) = -(inv_j.asDiagonal() * motor.chain.StiffnessMatrix());
  ss.a.block(n, n, n, n) = -(inv_j.asDiagonal() * motor.chain.DampingMatrix());
  ss.a.block(n, cur, n, 1) = inv_j.cwiseProduct(bt);
  ss.a.block(cur, n, 1, n) = -bt.transpose() / motor.l_h;
  ss.a(cur, cur) = -r_total / motor.l_h;
  ss.b = Eigen::VectorXd::Zero(nx);
  ss.b[cur] = 1.0 / motor.l_h;
  ss.c = Eigen::MatrixXd::Zero(2, nx);
  ss.c(0, cur) = -circuit.SeriesOhm();
  ss.c(1, cur) = 1.0;
  ss.d << 1.0, 0.0;
  return ss;
}

Eigen::MatrixXd BalancedExp(const Eigen::MatrixXd& m) {
  // Parlett-Reinsch balancing with radix 2 (exact in floating point).
  Eigen::MatrixXd a = m;
  const Eigen::Index n = a.rows();
  Eigen::VectorXd d = Eigen::VectorXd::Ones(n);
  for (bool done = false; !done;) {
    done = true;
    for (Eigen::Index i = 0; i < n; ++i) {
      const double c = a.col(i).cwiseAbs().sum() - std::abs(a(i, i));
      const double r = a.row(i).cwiseAbs().sum() - std::abs(a(i, i));
      if (c == 0.0 || r == 0.0) continue;
      double f = 1.0, cs = c;
      while (cs < r / 2.0) {
        f *= 2.0;
        cs *= 4.0;
      }
      while (cs > r * 2.0) {
        f /= 2.0;
        cs /= 4.0;
      }
      if ((cs + r) / f < 0.95 * (c + r)) {
        done = false;
        d[i] *= f;
        a.row(i) /= f;
        a.col(i) *= f;
      }
    }
  }
  const Eigen::MatrixXd e = a.exp();
  return d.asDiagonal() * e * d.cwiseInverse().asDiagonal();
}

TimeDomainSimulator::TimeDomainSimulator(const ClampedMotor& motor,
                                         const TimeDomainOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("time-domain options: " + why);
  const StateSpace ss = ClampedMotorStateSpace(motor, options.circuit);
  const double ts = 1.0 / options.sample_rate_hz;
  const auto nx = ss.a.rows();
  const int points = options.hold == InputHold::kZeroOrder ? 1 : options.hold_points;
  first_tap_ = options.hold == InputHold::kZeroOrder ? 0 : 1 - points / 2;

  // Augmented system in sigma = t / Ts: [x; w_0..w_{P-1}] with w_j = sigma^j
  // (w_j' = j w_{j-1}, w(0) = e_0) driving x through B Ts w_j, one j at a time.
  Eigen::MatrixXd gamma(nx, points);
  for (int j = 0; j < points; ++j) {
    Eigen::MatrixXd e = Eigen::MatrixXd::Zero(nx + points, nx + points);
    e.topLeftCorner(nx, nx) = ss.a * ts;
    e.block(0, nx + j, nx, 1) = ss.b * ts;
    for (int k = 1; k < points; ++k) e(nx + k, nx + k - 1) = k;
    const Eigen::MatrixXd phi = BalancedExp(e);
    if (j == 0) ad_ = phi.topLeftCorner(nx, nx);
    gamma.col(j) = phi.block(0, nx, nx, 1);
  }
  lambda_ = options.hold == InputHold::kZeroOrder
                ? gamma
                : Eigen::MatrixXd(gamma * LagrangeMonomials(first_tap_, points));
  if (!ad_.allFinite() || !lambda_.allFinite())
    throw std::invalid_argument("time-domain discretisation is not finite");
  c_ = ss.c;
  d_ = ss.d;
  x_ = Eigen::VectorXd::Zero(nx);
  taps_.resize(points);
}

void TimeDomainSimulator::Reset() { x_.setZero(); }

double TimeDomainSimulator::Input(const std::vector<double>& u, std::ptrdiff_t n) const {
  return n >= 0 && n < static_cast<std::ptrdiff_t>(u.size()) ? u[static_cast<std::size_t>(n)] : 0.0;
}

void TimeDomainSimulator::Run(const std::vector<double>& u_amp, std::size_t first, std::size_t last,
                              double* voltage_v, double* current_a) {
  Eigen::VectorXd next(x_.size());
  for (std::size_t n = first; n < last; ++n) {
    const auto sn = static_cast<std::ptrdiff_t>(n);
    const double u = Input(u_amp, sn);
    voltage_v[n - first] = c_.row(0).dot(x_) + d_[0] * u;
    current_a[n - first] = c_.row(1).dot(x_) + d_[1] * u;
    for (Eigen::Index q = 0; q < taps_.size(); ++q) taps_[q] = Input(u_amp, sn + first_tap_ + q);
    next.noalias() = ad_ * x_;
    next.noalias() += lambda_ * taps_;
    x_ = next;
  }
}

Recording SimulateRecording(const ClampedMotor& motor, const TimeDomainOptions& options,
                            const std::vector<double>& amplifier_v, std::size_t period_samples,
                            const ChannelNoise& noise) {
  TimeDomainSimulator sim(motor, options);
  Recording rec;
  rec.sample_rate_hz = options.sample_rate_hz;
  rec.period_samples = period_samples;
  rec.voltage_v.resize(amplifier_v.size());
  rec.current_a.resize(amplifier_v.size());
  sim.Run(amplifier_v, 0, amplifier_v.size(), rec.voltage_v.data(), rec.current_a.data());
  AddChannelNoise(noise, &rec);
  return rec;
}

void AddChannelNoise(const ChannelNoise& noise, Recording* recording) {
  std::mt19937_64 rng(noise.seed);
  std::normal_distribution<double> unit(0.0, 1.0);
  for (std::size_t t = 0; t < recording->voltage_v.size(); ++t) {
    recording->voltage_v[t] += noise.voltage_v * unit(rng);
    recording->current_a[t] += noise.current_a * unit(rng);
  }
}

}  // namespace eol::analysis
