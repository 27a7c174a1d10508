#include "analysis/model/two_mass.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <locale>
#include <numbers>
#include <sstream>

#include "analysis/fit/least_squares.h"
#include "analysis/text.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;
constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kDelayScale = 1e-3;  // tau is fitted in ms: theta = tau / 1 ms
constexpr double kZetaScale = 1e-2;   // zeta_ar is fitted in %

// Which parameters theta holds, in order: ln g, ln f_ar, ln f_r, 100 zeta_ar, [beta], [tau].
// zeta_ar and beta are linear: either may be near zero (the friction to ground can carry all
// the damping), where a log parameter would make the information matrix singular.
struct Layout {
  bool friction = false;
  bool delay = false;
  int size() const { return 4 + (friction ? 1 : 0) + (delay ? 1 : 0); }
};

TwoMassResponse FromTheta(const Eigen::VectorXd& t, const Layout& l) {
  TwoMassResponse r;
  r.gain_rad_per_s2_per_a = std::exp(t[0]);
  r.f_ar_hz = std::exp(t[1]);
  r.f_r_hz = std::exp(t[2]);
  r.zeta_ar = t[3] * kZetaScale;
  int i = 4;
  if (l.friction) r.friction_per_s = t[i++];
  if (l.delay) r.delay_s = t[i] * kDelayScale;
  return r;
}

Eigen::VectorXd ToTheta(const TwoMassResponse& r, const Layout& l) {
  Eigen::VectorXd t(l.size());
  t[0] = std::log(r.gain_rad_per_s2_per_a);
  t[1] = std::log(r.f_ar_hz);
  t[2] = std::log(r.f_r_hz);
  t[3] = r.zeta_ar / kZetaScale;
  int i = 4;
  if (l.friction) t[i++] = r.friction_per_s;
  if (l.delay) t[i] = r.delay_s / kDelayScale;
  return t;
}

struct Data {
  std::vector<double> f;
  std::vector<Cplx> h;
  std::vector<double> scale;  // sqrt(2) / sigma
};

void Residual(const TwoMassResponse& m, const Data& d, Eigen::VectorXd* r) {
  const std::size_t n = d.f.size();
  r->resize(static_cast<Eigen::Index>(2 * n));
  for (std::size_t k = 0; k < n; ++k) {
    const Cplx e = (m.At(d.f[k]) - d.h[k]) * d.scale[k];
    (*r)[static_cast<Eigen::Index>(2 * k)] = e.real();
    (*r)[static_cast<Eigen::Index>(2 * k + 1)] = e.imag();
  }
}

// Rejects theta whose log-parameters overflow exp(); the minimiser then shortens the step.
void GuardedResidual(const Eigen::VectorXd& theta, const Data& data, const Layout& layout,
                     Eigen::VectorXd* r) {
  if (!theta.allFinite() || theta.head(3).cwiseAbs().maxCoeff() > 700.0) {
    r->setConstant(static_cast<Eigen::Index>(2 * data.f.size()),
                   std::numeric_limits<double>::quiet_NaN());
    return;
  }
  Residual(FromTheta(theta, layout), data, r);
}

// Central differences: the model is cheap and smooth in theta.
void CentralDifferenceJacobian(const Eigen::VectorXd& theta, const Data& data, const Layout& layout,
                               Eigen::MatrixXd* jac) {
  jac->resize(static_cast<Eigen::Index>(2 * data.f.size()), layout.size());
  Eigen::VectorXd rp, rm;
  for (int i = 0; i < layout.size(); ++i) {
    const double h = 1e-6 * std::max(1.0, std::abs(theta[i]));
    Eigen::VectorXd tp = theta, tm = theta;
    tp[i] += h;
    tm[i] -= h;
    GuardedResidual(tp, data, layout, &rp);
    GuardedResidual(tm, data, layout, &rm);
    jac->col(i) = (rp - rm) / (2.0 * h);
  }
}

// Why the options or the FRF cannot be fitted; empty when they can.
std::string InputProblem(const Frf& frf, const TwoMassFitOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) return "options: " + why;
  if (!frf.Validate(&why)) return why;
  if (frf.quantity != Quantity::kMobility)
    return std::string("quantity is ") + ToString(frf.quantity) + ", the two-mass fit needs " +
           ToString(Quantity::kMobility);
  return "";
}

// The lines in the options' band (every line when both ends are 0), with their weights.
Data LinesInBand(const Frf& frf, const TwoMassFitOptions& o) {
  Data d;
  const bool all = o.f_lo_hz == 0.0 && o.f_hi_hz == 0.0;
  for (std::size_t k = 0; k < frf.size(); ++k) {
    if (!all && (frf.freq_hz[k] < o.f_lo_hz || frf.freq_hz[k] > o.f_hi_hz)) continue;
    d.f.push_back(frf.freq_hz[k]);
    d.h.push_back(frf.value[k]);
    d.scale.push_back(frf.has_sigma() ? std::numbers::sqrt2 / frf.sigma[k] : std::numbers::sqrt2);
  }
  return d;
}

// Start: the |H| maximum is the resonance, the |H| minimum below it the anti-resonance, the
// gain from the rigid body on the lowest lines, zeta_ar the best of a few. Returns false with
// *why when |H| shows no resonance or anti-resonance.
bool StartFromPeaks(const Data& d, const Layout& layout, TwoMassResponse* start, std::string* why) {
  const std::size_t n = d.f.size();
  std::size_t i_max = 0;
  for (std::size_t k = 1; k < n; ++k)
    if (std::abs(d.h[k]) > std::abs(d.h[i_max])) i_max = k;
  if (i_max == 0) {
    *why = "no resonance: |H| has its maximum at the lowest line";
    return false;
  }
  std::size_t i_min = 0;
  for (std::size_t k = 1; k < i_max; ++k)
    if (std::abs(d.h[k]) < std::abs(d.h[i_min])) i_min = k;
  if (i_min == 0) {
    *why = "no anti-resonance: |H| has no minimum below its maximum at " +
           std::to_string(d.f[i_max]) + " Hz";
    return false;
  }
  start->f_ar_hz = d.f[i_min];
  start->f_r_hz = d.f[i_max];
  {
    // Rigid body on the lowest lines: |H| ~ g / w.
    std::vector<double> g;
    for (std::size_t k = 0; k < std::min<std::size_t>(5, i_min); ++k)
      g.push_back(std::abs(d.h[k]) * kTwoPi * d.f[k]);
    std::sort(g.begin(), g.end());
    start->gain_rad_per_s2_per_a = g[g.size() / 2];
  }
  double best = std::numeric_limits<double>::infinity();
  TwoMassResponse trial = *start;
  Eigen::VectorXd r;
  for (double zeta : {0.002, 0.005, 0.01, 0.02, 0.05, 0.1, 0.2}) {
    trial.zeta_ar = zeta;
    Residual(trial, d, &r);
    if (r.allFinite() && r.squaredNorm() < best) {
      best = r.squaredNorm();
      start->zeta_ar = zeta;
    }
  }
  if (layout.friction) start->friction_per_s = 0.1 * kTwoPi * d.f.front();
  return true;
}

LeastSquaresOutcome Minimise(const Data& d, const Layout& layout, int max_iterations,
                             Eigen::VectorXd* theta) {
  LeastSquaresProblem problem;
  problem.parameters = layout.size();
  problem.residuals = static_cast<int>(2 * d.f.size());
  problem.residual = [&](const Eigen::VectorXd& t, Eigen::VectorXd* res) {
    GuardedResidual(t, d, layout, res);
  };
  problem.jacobian = [&](const Eigen::VectorXd& t, Eigen::MatrixXd* jac) {
    CentralDifferenceJacobian(t, d, layout, jac);
  };
  LeastSquaresSettings settings;
  settings.max_iterations = max_iterations;
  return MinimizeLeastSquares(problem, theta, settings);
}

// chi2 (the noise estimated from the residual without sigma) and the normalised rms error of
// out->response; returns the noise variance the covariance is scaled by.
double FillChi2(const Data& d, const Layout& layout, bool has_sigma, TwoMassFit* out) {
  const std::size_t n = d.f.size();
  Eigen::VectorXd r;
  Residual(out->response, d, &r);
  out->dof = static_cast<int>(2 * n) - layout.size();
  const double chi2_raw = r.squaredNorm();
  out->sigma_estimated = !has_sigma;
  const double noise_var = out->sigma_estimated ? chi2_raw / out->dof : 1.0;
  out->chi2 = chi2_raw / noise_var;
  out->chi2_per_dof = out->chi2 / out->dof;
  double err2 = 0.0, h2 = 0.0;
  for (std::size_t k = 0; k < n; ++k) {
    err2 += std::norm(out->response.At(d.f[k]) - d.h[k]);
    h2 += std::norm(d.h[k]);
  }
  out->rms_relative_error = std::sqrt(err2 / h2);
  return noise_var;
}

// The parameters with their sigmas from the covariance in theta, scaled by the noise estimate
// and, when the model error dominates, by chi2/dof (Birge ratio). Returns whether the
// covariance is finite and positive (the sigmas are NaN otherwise).
bool FillParams(const Data& d, const Layout& layout, const Eigen::VectorXd& theta, double noise_var,
                TwoMassFit* out) {
  Eigen::MatrixXd jac;
  CentralDifferenceJacobian(theta, d, layout, &jac);
  const double inflate = std::max(1.0, out->chi2_per_dof);
  Eigen::MatrixXd cov = Eigen::MatrixXd::Constant(layout.size(), layout.size(),
                                                  std::numeric_limits<double>::quiet_NaN());
  const Eigen::MatrixXd jtj = jac.transpose() * jac;
  const Eigen::LDLT<Eigen::MatrixXd> ldlt(jtj);
  bool cov_ok = false;
  if (jac.allFinite() && ldlt.info() == Eigen::Success && ldlt.isPositive()) {
    cov = ldlt.solve(Eigen::MatrixXd::Identity(layout.size(), layout.size())) * noise_var * inflate;
    cov_ok = cov.allFinite() && cov.diagonal().minCoeff() > 0.0;
  }
  const TwoMassResponse& m = out->response;
  auto add = [&](const char* name, const char* unit, double value, double sigma) {
    out->params.push_back(FittedParameter{name, unit, value, cov_ok ? sigma : std::nan("")});
  };
  auto sd = [&](int i) { return std::sqrt(cov(i, i)); };
  add("g_rad_per_s2_per_a", "rad/s^2/A", m.gain_rad_per_s2_per_a, m.gain_rad_per_s2_per_a * sd(0));
  add("f_ar_hz", "Hz", m.f_ar_hz, m.f_ar_hz * sd(1));
  add("f_r_hz", "Hz", m.f_r_hz, m.f_r_hz * sd(2));
  add("zeta_ar", "1", m.zeta_ar, kZetaScale * sd(3));
  int i = 4;
  if (layout.friction) {
    add("friction_per_s", "1/s", m.friction_per_s, sd(i));
    ++i;
  }
  if (layout.delay) add("delay_s", "s", m.delay_s, kDelayScale * sd(i));
  return cov_ok;
}

// Why the fit is not a usable two-mass response; empty when it is one.
std::string RejectFit(const TwoMassFit& out, bool cov_ok) {
  const TwoMassResponse& m = out.response;
  std::ostringstream os = MessageStream();
  if (!(m.f_r_hz > m.f_ar_hz)) {
    os << "not a two-mass response: the fit put the resonance (" << m.f_r_hz
       << " Hz) at or below the anti-resonance (" << m.f_ar_hz << " Hz)";
    return os.str();
  }
  if (!cov_ok) return "covariance is not finite: the data do not determine every parameter";
  if (m.zeta_ar < -2.0 * out.params[3].sigma) {
    os << "not a passive two-mass response: zeta_ar = " << m.zeta_ar << " +- "
       << out.params[3].sigma << " is significantly negative";
    return os.str();
  }
  return "";
}

std::string UsableMessage(const TwoMassFit& out, std::size_t n) {
  const TwoMassResponse& m = out.response;
  std::ostringstream os = MessageStream();
  os << "two-mass fit over " << n << " lines: anti-resonance " << m.f_ar_hz << " +- "
     << out.params[1].sigma << " Hz, resonance " << m.f_r_hz << " +- " << out.params[2].sigma
     << " Hz, chi2/dof " << out.chi2_per_dof << " (dof " << out.dof << "), normalised rms error "
     << out.rms_relative_error;
  if (m.zeta_ar < 0.0)
    os << "; zeta_ar is negative but within 2 sigma of 0: the coupling damping is not resolved"
          " (the friction to ground carries the damping)";
  if (out.sigma_estimated)
    os << "; no sigma given: noise estimated from the residual";
  else if (out.chi2_per_dof > 1.0 + 5.0 * std::sqrt(2.0 / out.dof))
    os << "; chi2/dof above 1: the model error exceeds the noise, sigmas scaled by sqrt(chi2/dof)";
  return os.str();
}

}  // namespace

Cplx TwoMassResponse::At(double f_hz) const {
  const Cplx s(0.0, kTwoPi * f_hz);
  const double w_ar = kTwoPi * f_ar_hz;
  const double r1 = (f_ar_hz / f_r_hz) * (f_ar_hz / f_r_hz);
  const double r2 = 1.0 - r1;
  const Cplx coupling = 2.0 * zeta_ar * w_ar * s + w_ar * w_ar;  // (c s + k) / J2
  const Cplx n = s * s + coupling;
  const Cplx h = gain_rad_per_s2_per_a * n / ((r1 * s + friction_per_s) * n + r2 * s * coupling);
  return delay_s == 0.0 ? h : h * std::exp(-s * delay_s);
}

Frf TwoMassResponse::Evaluate(const std::vector<double>& freq_hz) const {
  Frf h;
  h.quantity = Quantity::kMobility;
  h.method = "model";
  h.freq_hz = freq_hz;
  for (double f : freq_hz) h.value.push_back(At(f));
  return h;
}

Cplx TwoMassSystem::Mobility(double f_hz) const {
  const Cplx s(0.0, kTwoPi * f_hz);
  const Cplx spring = c_nms_per_rad * s + k_nm_per_rad;
  const Cplx n = j2_kg_m2 * s * s + spring;
  return kt_nm_per_a * n / ((j1_kg_m2 * s + b1_nms_per_rad) * n + j2_kg_m2 * s * spring);
}

TwoMassResponse TwoMassSystem::Response() const {
  const double j_tot = j1_kg_m2 + j2_kg_m2;
  TwoMassResponse r;
  r.gain_rad_per_s2_per_a = kt_nm_per_a / j_tot;
  const double w_ar = std::sqrt(k_nm_per_rad / j2_kg_m2);
  r.f_ar_hz = w_ar / kTwoPi;
  r.f_r_hz = std::sqrt(k_nm_per_rad * j_tot / (j1_kg_m2 * j2_kg_m2)) / kTwoPi;
  r.zeta_ar = c_nms_per_rad / (2.0 * std::sqrt(k_nm_per_rad * j2_kg_m2));
  r.friction_per_s = b1_nms_per_rad / j_tot;
  return r;
}

TwoMassSystem TwoMassSystem::FromResponse(const TwoMassResponse& r, double kt) {
  TwoMassSystem m;
  const double j_tot = kt / r.gain_rad_per_s2_per_a;
  const double r1 = (r.f_ar_hz / r.f_r_hz) * (r.f_ar_hz / r.f_r_hz);
  const double w_ar = kTwoPi * r.f_ar_hz;
  m.kt_nm_per_a = kt;
  m.j1_kg_m2 = r1 * j_tot;
  m.j2_kg_m2 = (1.0 - r1) * j_tot;
  m.k_nm_per_rad = m.j2_kg_m2 * w_ar * w_ar;
  m.c_nms_per_rad = 2.0 * r.zeta_ar * w_ar * m.j2_kg_m2;
  m.b1_nms_per_rad = r.friction_per_s * j_tot;
  return m;
}

bool TwoMassFitOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(f_lo_hz >= 0.0 && f_hi_hz >= 0.0)) return fail("f_lo_hz and f_hi_hz must not be negative");
  if (f_hi_hz > 0.0 && !(f_hi_hz > f_lo_hz)) return fail("f_hi_hz must be greater than f_lo_hz");
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  return true;
}

const FittedParameter* TwoMassFit::Find(const std::string& name) const {
  for (const FittedParameter& p : params)
    if (p.name == name) return &p;
  return nullptr;
}

TwoMassFit FitTwoMass(const Frf& frf, const TwoMassFitOptions& o) {
  TwoMassFit out;
  out.termination = Termination::kInvalidInput;
  if (const std::string why = InputProblem(frf, o); !why.empty()) {
    out.message = "invalid input: " + why;
    return out;
  }
  const Layout layout{o.fit_friction, o.fit_delay};
  const Data d = LinesInBand(frf, o);
  const std::size_t n = d.f.size();
  if (n < static_cast<std::size_t>(2 * layout.size())) {
    out.message = "invalid input: " + std::to_string(n) + " lines in the band, need at least " +
                  std::to_string(2 * layout.size());
    return out;
  }
  TwoMassResponse start;
  if (!StartFromPeaks(d, layout, &start, &out.message)) {
    out.termination = Termination::kFailed;
    return out;
  }

  Eigen::VectorXd theta = ToTheta(start, layout);
  const LeastSquaresOutcome lm = Minimise(d, layout, o.max_iterations, &theta);
  out.termination = lm.termination;
  out.response = FromTheta(theta, layout);
  const double noise_var = FillChi2(d, layout, frf.has_sigma(), &out);
  const bool cov_ok = FillParams(d, layout, theta, noise_var, &out);

  if (!lm.converged) {
    std::ostringstream os = MessageStream();
    os << "Levenberg-Marquardt " << ToString(out.termination) << " (MINPACK status "
       << lm.minpack_status << ") from f_ar = " << start.f_ar_hz << " Hz, f_r = " << start.f_r_hz
       << " Hz";
    out.message = os.str();
    return out;
  }
  out.message = RejectFit(out, cov_ok);
  if (!out.message.empty()) return out;
  out.usable = true;
  out.message = UsableMessage(out, n);
  return out;
}

}  // namespace eol::analysis
