#include "analysis/gap/calibration.h"

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>

#include "analysis/fit/least_squares.h"

namespace eol::analysis {
namespace {

double RelativeMisfit(const Frf& h, const NominalNetwork& n) {
  double num = 0.0, den = 0.0;
  for (std::size_t k = 0; k < h.size(); ++k) {
    num += std::norm(h.value[k] - n.At(h.freq_hz[k]));
    den += std::norm(h.value[k]);
  }
  return den > 0.0 ? std::sqrt(num / den) : 0.0;
}

CalibrationSummary CalibrateImpedance(const Frf& sim, const CalibrationOptions& o) {
  CalibrationSummary s;
  const FitSummary fit = FitMotionalResonance(sim, o.fit);
  s.params = fit.params;
  s.chi2_per_dof = fit.chi2_per_dof;
  s.sigma_estimated = fit.sigma_estimated;
  s.nominal.quantity = Quantity::kImpedanceOhm;
  s.nominal.motional = fit.Model();
  s.nominal.inertia_kg_m2 = o.inertia_kg_m2;
  if (!fit.usable) {
    s.message = "the nominal model does not fit the simulation: " + fit.message;
    return s;
  }
  s.misfit_rel_rms = RelativeMisfit(sim, s.nominal);
  s.usable = true;
  s.message = "nominal R + sL + parallel RLC fitted to the simulation: " + fit.message;
  return s;
}

CalibrationSummary CalibrateMobility(const Frf& sim, const CalibrationOptions& o) {
  CalibrationSummary s;
  s.nominal.quantity = Quantity::kMobility;
  s.nominal.inertia_kg_m2 = o.inertia_kg_m2;
  s.sigma_estimated = !sim.has_sigma();
  // Real least squares in (u, v): rows Re and Im of sqrt(w_k) (s_k u + v - 1/M_k).
  const std::size_t n = sim.size();
  Eigen::MatrixXd a(2 * n, 2);
  Eigen::VectorXd b(2 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::complex<double> m = sim.value[k];
    const double w = sim.has_sigma() ? std::norm(m) / sim.sigma[k] : std::norm(m);
    const double sw = std::sqrt(2.0) * w;  // each real residual of unit variance
    const double omega = 2.0 * std::numbers::pi * sim.freq_hz[k];
    const std::complex<double> inv = 1.0 / m;
    a(static_cast<long>(2 * k), 0) = 0.0;
    a(static_cast<long>(2 * k), 1) = sw;
    b(static_cast<long>(2 * k)) = sw * inv.real();
    a(static_cast<long>(2 * k + 1), 0) = sw * omega;
    a(static_cast<long>(2 * k + 1), 1) = 0.0;
    b(static_cast<long>(2 * k + 1)) = sw * inv.imag();
  }
  const Eigen::Matrix2d ata = a.transpose() * a;
  const Eigen::Vector2d x = ata.ldlt().solve(a.transpose() * b);
  if (!(x(0) > 0.0) || !x.allFinite()) {
    s.message =
        "the rigid-shaft model does not fit the simulation (1/g = " + std::to_string(x(0)) + ")";
    return s;
  }
  // Maximum likelihood on M itself from there: theta = (ln g, a / scale).
  const double a_scale = std::max(std::abs(x(1) / x(0)), 1.0);
  std::vector<double> scale(n, std::sqrt(2.0));
  if (sim.has_sigma())
    for (std::size_t k = 0; k < n; ++k) scale[k] = std::sqrt(2.0) / sim.sigma[k];
  auto model = [&](const Eigen::VectorXd& t) {
    return RigidShaftMobility{std::exp(t(0)), t(1) * a_scale};
  };
  LeastSquaresProblem problem;
  problem.parameters = 2;
  problem.residuals = static_cast<int>(2 * n);
  problem.residual = [&](const Eigen::VectorXd& t, Eigen::VectorXd* r) {
    const RigidShaftMobility m = model(t);
    r->resize(problem.residuals);
    for (std::size_t k = 0; k < n; ++k) {
      const std::complex<double> d = (m.At(sim.freq_hz[k]) - sim.value[k]) * scale[k];
      (*r)(static_cast<long>(2 * k)) = d.real();
      (*r)(static_cast<long>(2 * k + 1)) = d.imag();
    }
  };
  problem.jacobian = [&](const Eigen::VectorXd& t, Eigen::MatrixXd* j) {
    j->resize(problem.residuals, 2);
    const RigidShaftMobility m = model(t);
    for (std::size_t k = 0; k < n; ++k) {
      const std::complex<double> sk(0.0, 2.0 * std::numbers::pi * sim.freq_hz[k]);
      const std::complex<double> h = m.At(sim.freq_hz[k]);
      // dM/d ln g = M;  dM/da = -M / (s + a), a = t1 * a_scale.
      const std::complex<double> d0 = h * scale[k];
      const std::complex<double> d1 = -h / (sk + m.damping_per_s) * a_scale * scale[k];
      (*j)(static_cast<long>(2 * k), 0) = d0.real();
      (*j)(static_cast<long>(2 * k + 1), 0) = d0.imag();
      (*j)(static_cast<long>(2 * k), 1) = d1.real();
      (*j)(static_cast<long>(2 * k + 1), 1) = d1.imag();
    }
  };
  Eigen::VectorXd theta(2);
  theta << std::log(1.0 / x(0)), x(1) / x(0) / a_scale;
  const LeastSquaresOutcome outcome = MinimizeLeastSquares(problem, &theta, LeastSquaresSettings{});
  Eigen::VectorXd r;
  problem.residual(theta, &r);
  const double chi2 = r.squaredNorm();
  const int dof = static_cast<int>(2 * n) - 2;
  const double noise = s.sigma_estimated ? chi2 / dof : 1.0;
  Eigen::MatrixXd jac, inverse;
  problem.jacobian(theta, &jac);
  double sg = std::numeric_limits<double>::quiet_NaN(), sa = sg;
  const double g = std::exp(theta(0)), damping = theta(1) * a_scale;
  if (InvertInformation(jac.transpose() * jac, &inverse)) {
    sg = g * std::sqrt(inverse(0, 0) * noise);
    sa = a_scale * std::sqrt(inverse(1, 1) * noise);
  }
  if (!outcome.converged) {
    s.message =
        "the rigid-shaft fit did not converge (" + std::string(ToString(outcome.termination)) + ")";
    return s;
  }
  s.nominal.rigid.gain_rad_per_s2_per_a = g;
  s.nominal.rigid.damping_per_s = std::max(damping, 0.0);
  s.params = {{"gain_rad_per_s2_per_a", "rad/s^2/A", g, sg}, {"damping_per_s", "1/s", damping, sa}};
  s.chi2_per_dof = chi2 / noise / dof;
  s.misfit_rel_rms = RelativeMisfit(sim, s.nominal);
  if (damping < 0.0) {
    s.message = "the rigid-shaft fit gives negative damping (" + std::to_string(damping) +
                " 1/s): an active shaft is not physical";
    return s;
  }
  s.usable = true;
  s.message = "rigid shaft g / (s + a) fitted to the simulation";
  return s;
}

}  // namespace

bool CalibrationOptions::IsValid(std::string* why) const {
  if (!(inertia_kg_m2 >= 0.0 && std::isfinite(inertia_kg_m2))) {
    if (why) *why = "inertia_kg_m2 must be finite and not negative (0: unknown)";
    return false;
  }
  return fit.IsValid(why);
}

CalibrationSummary CalibrateNominal(const Frf& sim, const CalibrationOptions& options) {
  CalibrationSummary s;
  std::string why;
  if (!options.IsValid(&why)) {
    s.message = "invalid options: " + why;
    return s;
  }
  if (!sim.Validate(&why)) {
    s.message = "invalid simulation: " + why;
    return s;
  }
  if (sim.size() < 10) {
    s.message = "the simulation has " + std::to_string(sim.size()) + " lines, at least 10 needed";
    return s;
  }
  return sim.quantity == Quantity::kMobility ? CalibrateMobility(sim, options)
                                             : CalibrateImpedance(sim, options);
}

}  // namespace eol::analysis
