#include "analysis/fit/modes_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <locale>
#include <numbers>
#include <sstream>

#include "analysis/fit/least_squares.h"
#include "analysis/fit/motional_jacobian.h"
#include "analysis/text.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

constexpr int kRefineSteps = 21;  // as resonance_fit.cc
constexpr int kRefinePasses = 2;
constexpr double kExcludeBandwidths = 0.25;
constexpr double kDistinctSigmas = 3.0;

int ParamCount(int modes) { return 2 + 3 * modes; }

Eigen::VectorXd ToTheta(const MultiModeImpedance& p) {
  Eigen::VectorXd t(ParamCount(static_cast<int>(p.modes.size())));
  t[0] = std::log(p.r_ohm);
  t[1] = std::log(p.l_h);
  for (std::size_t n = 0; n < p.modes.size(); ++n) {
    const auto i = static_cast<Eigen::Index>(2 + 3 * n);
    t[i] = std::log(p.modes[n].rp_ohm);
    t[i + 1] = std::log(p.modes[n].f0_hz);
    t[i + 2] = std::log(p.modes[n].q);
  }
  return t;
}

MultiModeImpedance FromTheta(const Eigen::VectorXd& t) {
  MultiModeImpedance p;
  p.r_ohm = std::exp(t[0]);
  p.l_h = std::exp(t[1]);
  for (Eigen::Index i = 2; i + 2 < t.size(); i += 3)
    p.modes.push_back({std::exp(t[i]), std::exp(t[i + 1]), std::exp(t[i + 2])});
  return p;
}

// Z and dZ/dtheta at one line, from motional_jacobian.h's single-mode derivatives.
void Evaluate(const MultiModeImpedance& p, double f_hz, Cplx* z, std::vector<Cplx>* dz) {
  dz->assign(static_cast<std::size_t>(ParamCount(static_cast<int>(p.modes.size()))), 0.0);
  *z = 0.0;
  for (std::size_t n = 0; n < p.modes.size(); ++n) {
    const MotionalImpedance m{p.r_ohm, p.l_h, p.modes[n].rp_ohm, p.modes[n].f0_hz, p.modes[n].q};
    const MotionalPoint pt = EvaluateMotional(m, f_hz);
    if (n == 0) {
      *z = pt.z;
      (*dz)[0] = pt.dz_dtheta[kParamR];
      (*dz)[1] = pt.dz_dtheta[kParamL];
    } else {
      *z += pt.dz_dtheta[kParamRp];  // Rp / D: the mode's own term
    }
    (*dz)[2 + 3 * n] = pt.dz_dtheta[kParamRp];
    (*dz)[3 + 3 * n] = pt.dz_dtheta[kParamF0];
    (*dz)[4 + 3 * n] = pt.dz_dtheta[kParamQ];
  }
}

struct Data {
  const std::vector<double>& f;
  const std::vector<Cplx>& z;
  std::vector<double> scale;  // sqrt(2) / sigma_k (sigma 1 when unknown)
};

void Residual(const Data& d, const MultiModeImpedance& p, Eigen::VectorXd* r) {
  r->resize(static_cast<Eigen::Index>(2 * d.f.size()));
  std::vector<Cplx> dz;
  for (std::size_t k = 0; k < d.f.size(); ++k) {
    Cplx z;
    Evaluate(p, d.f[k], &z, &dz);
    const Cplx e = (z - d.z[k]) * d.scale[k];
    (*r)[static_cast<Eigen::Index>(2 * k)] = e.real();
    (*r)[static_cast<Eigen::Index>(2 * k + 1)] = e.imag();
  }
}

void Jacobian(const Data& d, const MultiModeImpedance& p, Eigen::MatrixXd* j) {
  const int np = ParamCount(static_cast<int>(p.modes.size()));
  j->resize(static_cast<Eigen::Index>(2 * d.f.size()), np);
  std::vector<Cplx> dz;
  for (std::size_t k = 0; k < d.f.size(); ++k) {
    Cplx z;
    Evaluate(p, d.f[k], &z, &dz);
    for (int i = 0; i < np; ++i) {
      const Cplx e = dz[static_cast<std::size_t>(i)] * d.scale[k];
      (*j)(static_cast<Eigen::Index>(2 * k), i) = e.real();
      (*j)(static_cast<Eigen::Index>(2 * k + 1), i) = e.imag();
    }
  }
}

// A candidate start for M + 1 modes: (f, Q) of the new mode, the linear parameters solved.
struct SearchPoint {
  bool ok = false;
  double f0_hz = 0.0;
  double q = 0.0;
  double chi2 = std::numeric_limits<double>::infinity();
  MultiModeImpedance model;
};

// Variable projection for the new mode with the fitted modes' (f_n, Q_n) held. Basis per
// line: 1, j w / w_ref, 1/D_1 .. 1/D_M (fixed), 1/D_new; weighted inner product
// <a, b> = sum_k s_k^2 Re(conj(a_k) b_k).
class ModeSearch {
 public:
  ModeSearch(const Data& d, const MultiModeImpedance& fitted) : d_(d), fitted_(fitted) {
    const std::size_t k_lines = d.f.size();
    nf_ = 2 + static_cast<int>(fitted.modes.size());
    w_ref_ = 2.0 * std::numbers::pi * d.f.back();
    basis_.resize(k_lines, nf_);
    for (std::size_t k = 0; k < k_lines; ++k) {
      const auto row = static_cast<Eigen::Index>(k);
      basis_(row, 0) = 1.0;
      basis_(row, 1) = Cplx(0.0, 2.0 * std::numbers::pi * d.f[k] / w_ref_);
      for (std::size_t n = 0; n < fitted.modes.size(); ++n)
        basis_(row, static_cast<Eigen::Index>(2 + n)) =
            InverseDenominator(fitted.modes[n].f0_hz, fitted.modes[n].q, d.f[k]);
    }
    gram_ = Eigen::MatrixXd::Zero(nf_, nf_);
    rhs_ = Eigen::VectorXd::Zero(nf_);
    for (std::size_t k = 0; k < k_lines; ++k) {
      const double w = d.scale[k] * d.scale[k];
      const auto row = static_cast<Eigen::Index>(k);
      for (int a = 0; a < nf_; ++a) {
        rhs_[a] += w * (std::conj(basis_(row, a)) * d.z[k]).real();
        for (int b = 0; b < nf_; ++b)
          gram_(a, b) += w * (std::conj(basis_(row, a)) * basis_(row, b)).real();
      }
      zz_ += w * std::norm(d.z[k]);
    }
  }

  // Every Q of `qs` at f0, and the best in *best (index into qs in *best_q; untouched when
  // none is better). With c_k = 1 / (1 + j b_k), b_k = Q x_k, x_k = f_k / f0 - f0 / f_k and
  // m_k = 1 / (1 + b_k^2): Re(conj(B_a) c) = m (Br_a - Q x Bi_a), |c|^2 = m and
  // Re(conj(c) z) = m (zr - Q x zi), so the sums over lines are accumulated per Q with lines
  // outer and Q inner (vectorised, no complex division), and only the small system is per point.
  void Row(double f0_hz, const std::vector<double>& qs, SearchPoint* best, int* best_q) const {
    for (const MotionalMode& m : fitted_.modes)
      if (std::abs(f0_hz - m.f0_hz) < kExcludeBandwidths * m.f0_hz / m.q) return;
    const std::size_t nq = qs.size();
    const auto nf = static_cast<std::size_t>(nf_);
    std::vector<double> q2(nq), m(nq), cc(nq, 0.0), z1(nq, 0.0), z2(nq, 0.0);
    std::vector<double> re(nf * nq, 0.0), im(nf * nq, 0.0);  // [a * nq + i]
    std::vector<double> w_br(nf), w_x_bi(nf);
    for (std::size_t i = 0; i < nq; ++i) q2[i] = qs[i] * qs[i];
    for (std::size_t k = 0; k < d_.f.size(); ++k) {
      const double w = d_.scale[k] * d_.scale[k];
      const double x = d_.f[k] / f0_hz - f0_hz / d_.f[k];
      const double x2 = x * x;
      const auto row = static_cast<Eigen::Index>(k);
      for (std::size_t a = 0; a < nf; ++a) {
        const Cplx basis = basis_(row, static_cast<Eigen::Index>(a));
        w_br[a] = w * basis.real();
        w_x_bi[a] = w * x * basis.imag();
      }
      const double w_zr = w * d_.z[k].real(), w_x_zi = w * x * d_.z[k].imag();
      for (std::size_t i = 0; i < nq; ++i) {
        m[i] = 1.0 / (1.0 + q2[i] * x2);
        cc[i] += w * m[i];
        z1[i] += w_zr * m[i];
        z2[i] += w_x_zi * m[i];
      }
      for (std::size_t a = 0; a < nf; ++a)
        for (std::size_t i = 0; i < nq; ++i) {
          re[a * nq + i] += w_br[a] * m[i];
          im[a * nq + i] += w_x_bi[a] * m[i];
        }
    }
    Eigen::VectorXd cross(nf_);
    for (std::size_t i = 0; i < nq; ++i) {
      for (std::size_t a = 0; a < nf; ++a)
        cross[static_cast<Eigen::Index>(a)] = re[a * nq + i] - qs[i] * im[a * nq + i];
      SearchPoint p = Solve(f0_hz, qs[i], cross, cc[i], z1[i] - qs[i] * z2[i]);
      if (p.ok && p.chi2 < best->chi2) {
        *best = std::move(p);
        *best_q = static_cast<int>(i);
      }
    }
  }

  SearchPoint Grid(const std::vector<double>& fs, const std::vector<double>& qs, int* bi,
                   int* bj) const {
    SearchPoint best;
    for (std::size_t i = 0; i < fs.size(); ++i) {
      int j = -1;
      Row(fs[i], qs, &best, &j);
      if (j >= 0) {
        *bi = static_cast<int>(i);
        *bj = j;
      }
    }
    return best;
  }

 private:
  // The linear parameters with the new mode's column (cross: against the basis, cc: its own
  // norm, cz: against the data) for the new mode at (f0, Q).
  SearchPoint Solve(double f0_hz, double q, const Eigen::VectorXd& cross, double cc,
                    double cz) const {
    SearchPoint p;
    p.f0_hz = f0_hz;
    p.q = q;
    const int nt = nf_ + 1;
    Eigen::MatrixXd g(nt, nt);
    Eigen::VectorXd rhs(nt);
    g.topLeftCorner(nf_, nf_) = gram_;
    rhs.head(nf_) = rhs_;
    g.block(0, nf_, nf_, 1) = cross;
    g.block(nf_, 0, 1, nf_) = cross.transpose();
    g(nf_, nf_) = cc;
    rhs[nf_] = cz;
    const Eigen::VectorXd dscale = g.diagonal().cwiseSqrt().cwiseInverse();
    const Eigen::LDLT<Eigen::MatrixXd> ldlt(dscale.asDiagonal() * g * dscale.asDiagonal());
    if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().array() > 1e-12).all()) return p;
    const Eigen::VectorXd x = dscale.cwiseProduct(ldlt.solve(dscale.cwiseProduct(rhs)));
    if (!(x.array() > 0.0).all()) return p;
    p.ok = true;
    p.chi2 = zz_ - x.dot(rhs);
    p.model.r_ohm = x[0];
    p.model.l_h = x[1] / w_ref_;
    for (std::size_t n = 0; n < fitted_.modes.size(); ++n)
      p.model.modes.push_back(
          {x[static_cast<Eigen::Index>(2 + n)], fitted_.modes[n].f0_hz, fitted_.modes[n].q});
    p.model.modes.push_back({x[nf_], f0_hz, q});
    return p;
  }

  // 1 / (1 + j Q (f / f0 - f0 / f)), written out: the library's complex division (__divdc3,
  // guarded for infinities) took a third of the station's analysis time in this search.
  static Cplx InverseDenominator(double f0_hz, double q, double f_hz) {
    const double b = q * (f_hz / f0_hz - f0_hz / f_hz);
    const double m = 1.0 / (1.0 + b * b);
    return Cplx(m, -b * m);
  }

  const Data& d_;
  const MultiModeImpedance& fitted_;
  int nf_ = 0;
  double w_ref_ = 1.0;
  Eigen::MatrixXcd basis_;
  Eigen::MatrixXd gram_;
  Eigen::VectorXd rhs_;
  double zz_ = 0.0;
};

MultiModeImpedance FromSingle(const FitSummary& s) {
  const MotionalImpedance m = s.Model();
  return MultiModeImpedance{m.r_ohm, m.l_h, {{m.rp_ohm, m.f0_hz, m.q}}};
}

double Bic(double chi2_raw, int params, std::size_t k_lines, bool sigma_known) {
  const double n = 2.0 * static_cast<double>(k_lines);
  const double fit_term = sigma_known ? chi2_raw : n * std::log(chi2_raw / n);
  return fit_term + params * std::log(n);
}

// The start for the new mode: the best (f, Q) of a grid over the search range, then of local
// refinements around the best cell, with the linear parameters solved. Not ok when no (f, Q)
// gives positive linear parameters.
SearchPoint StartForNewMode(const Data& d, const MultiModeImpedance& fitted,
                            const ModesFitOptions& o, double f0_lo, double f0_hi) {
  const ModeSearch search(d, fitted);
  std::vector<double> fs = LogSpace(f0_lo, f0_hi, o.single.grid_f0);
  std::vector<double> qs = LogSpace(o.single.q_min, o.single.q_max, o.single.grid_q);
  int bi = -1, bj = -1;
  SearchPoint start = search.Grid(fs, qs, &bi, &bj);
  if (!start.ok) return start;
  for (int pass = 0; pass < kRefinePasses; ++pass) {
    const auto at = [](const std::vector<double>& v, int i) {
      return v[static_cast<std::size_t>(std::clamp(i, 0, static_cast<int>(v.size()) - 1))];
    };
    fs = LogSpace(at(fs, bi - 1), at(fs, bi + 1), kRefineSteps);
    qs = LogSpace(at(qs, bj - 1), at(qs, bj + 1), kRefineSteps);
    int ri = -1, rj = -1;
    SearchPoint refined = search.Grid(fs, qs, &ri, &rj);
    if (!refined.ok || !(refined.chi2 < start.chi2)) break;
    start = std::move(refined);
    bi = ri;
    bj = rj;
  }
  return start;
}

// Levenberg-Marquardt in theta = ln p over `modes` modes; *theta ends at the fit.
LeastSquaresOutcome Minimise(const Data& d, int modes, int max_iterations, Eigen::VectorXd* theta) {
  LeastSquaresProblem problem;
  problem.parameters = ParamCount(modes);
  problem.residuals = static_cast<int>(2 * d.f.size());
  problem.residual = [&](const Eigen::VectorXd& t, Eigen::VectorXd* r) {
    Residual(d, FromTheta(t), r);
  };
  problem.jacobian = [&](const Eigen::VectorXd& t, Eigen::MatrixXd* j) {
    Jacobian(d, FromTheta(t), j);
  };
  LeastSquaresSettings settings;
  settings.max_iterations = max_iterations;
  return MinimizeLeastSquares(problem, theta, settings);
}

// chi2 (the noise estimated from the residual without sigma), the candidate's chi2 and BIC,
// the covariance and the parameters of `fit` (theta = its ln p). Returns whether the
// covariance is finite.
bool FillStatistics(const Data& d, const MultiModeImpedance& fit, const Eigen::VectorXd& theta,
                    bool sigma_known, FitSummary* s, ModeOrderCandidate* candidate) {
  const int m = static_cast<int>(fit.modes.size());
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  Residual(d, fit, &r);
  Jacobian(d, fit, &jac);
  const double chi2_raw = r.squaredNorm();
  const double noise_var = sigma_known ? 1.0 : chi2_raw / s->dof;
  if (!sigma_known) s->estimated_sigma = std::sqrt(noise_var);
  s->chi2 = chi2_raw / noise_var;
  s->chi2_per_dof = s->chi2 / s->dof;
  candidate->chi2 = chi2_raw;
  candidate->bic = Bic(chi2_raw, ParamCount(m), d.f.size(), sigma_known);

  Eigen::MatrixXd c_log;
  const bool covariance_ok =
      r.allFinite() && jac.allFinite() && InvertInformation(jac.transpose() * jac, &c_log);
  const Eigen::VectorXd natural = theta.array().exp().matrix();
  if (covariance_ok)
    s->covariance = natural.asDiagonal() * (c_log * noise_var) * natural.asDiagonal();
  auto sigma = [&](int i) { return covariance_ok ? std::sqrt(s->covariance(i, i)) : std::nan(""); };
  s->params.push_back({"R_ohm", "ohm", fit.r_ohm, sigma(0)});
  s->params.push_back({"L_h", "H", fit.l_h, sigma(1)});
  for (int n = 0; n < m; ++n) {
    const std::string k = std::to_string(n + 1);
    const MotionalMode& mode = fit.modes[static_cast<std::size_t>(n)];
    s->params.push_back({"Rp" + k + "_ohm", "ohm", mode.rp_ohm, sigma(2 + 3 * n)});
    s->params.push_back({"f" + k + "_hz", "Hz", mode.f0_hz, sigma(3 + 3 * n)});
    s->params.push_back({"Q" + k, "1", mode.q, sigma(4 + 3 * n)});
  }
  return covariance_ok;
}

// Whether every mode of the fit (finite covariance) is a resonance: inside the search range,
// with a significant peak, distinct from the mode below it. Writes the first failure to os.
bool ModesAreResolved(const FitSummary& s, const MultiModeImpedance& fit, const ModesFitOptions& o,
                      double f0_lo, double f0_hi, std::ostream& os) {
  const auto sigma = [&](int i) { return std::sqrt(s.covariance(i, i)); };
  const double step = std::log(f0_hi / f0_lo) / (o.single.grid_f0 - 1);
  const int m = static_cast<int>(fit.modes.size());
  for (int n = 0; n < m; ++n) {
    const MotionalMode& mode = fit.modes[static_cast<std::size_t>(n)];
    const double rp_sigma = sigma(2 + 3 * n);
    if (!(mode.f0_hz >= f0_lo * std::exp(step) && mode.f0_hz <= f0_hi * std::exp(-step))) {
      os << "mode at " << mode.f0_hz << " Hz is at or beyond the edge of the search range";
      return false;
    }
    if (!(mode.rp_ohm >= o.single.min_rp_significance * rp_sigma)) {
      os << "mode at " << mode.f0_hz << " Hz: Rp = " << mode.rp_ohm << " +- " << rp_sigma
         << " ohm is below " << o.single.min_rp_significance << " standard deviations";
      return false;
    }
    if (n > 0) {
      const MotionalMode& prev = fit.modes[static_cast<std::size_t>(n - 1)];
      const double sep_sigma = std::hypot(sigma(3 + 3 * n), sigma(3 * n));
      if (!(mode.f0_hz - prev.f0_hz > kDistinctSigmas * sep_sigma)) {
        os << "modes at " << prev.f0_hz << " and " << mode.f0_hz
           << " Hz are not distinct within their uncertainty";
        return false;
      }
    }
  }
  return true;
}

// Fits M + 1 modes starting from the M-mode model; fills *candidate and returns the summary.
FitSummary AddMode(const Data& d, const MultiModeImpedance& fitted, const ModesFitOptions& o,
                   double f0_lo, double f0_hi, bool sigma_known, ModeOrderCandidate* candidate) {
  const int m = static_cast<int>(fitted.modes.size()) + 1;
  FitSummary s;
  s.model = "R+sL+" + std::to_string(m) + "x parallel-RLC";
  s.sigma_estimated = !sigma_known;
  s.dof = static_cast<int>(2 * d.f.size()) - ParamCount(m);
  candidate->modes = m;
  std::ostringstream os = MessageStream();

  const SearchPoint start = StartForNewMode(d, fitted, o, f0_lo, f0_hi);
  if (!start.ok) {
    s.termination = Termination::kFailed;
    os << "no start for mode " << m << ": no (f, Q) gives positive linear parameters";
    s.message = candidate->message = os.str();
    return s;
  }
  Eigen::VectorXd theta = ToTheta(start.model);
  const LeastSquaresOutcome lm = Minimise(d, m, o.single.max_iterations, &theta);
  s.iterations = lm.iterations;
  s.termination = lm.termination;

  // Modes in ascending frequency (theta reordered to match).
  MultiModeImpedance fit = FromTheta(theta);
  std::sort(fit.modes.begin(), fit.modes.end(),
            [](const MotionalMode& a, const MotionalMode& b) { return a.f0_hz < b.f0_hz; });
  theta = ToTheta(fit);
  const bool covariance_ok = FillStatistics(d, fit, theta, sigma_known, &s, candidate);

  if (!lm.converged) {
    os << "Levenberg-Marquardt did not converge for " << m << " modes (" << ToString(lm.termination)
       << ", MINPACK status " << lm.minpack_status << ")";
  } else if (!covariance_ok) {
    os << m << " modes are not determined by the data (singular Jacobian)";
  } else if (ModesAreResolved(s, fit, o, f0_lo, f0_hi, os)) {
    s.usable = true;
    os << m << " modes:";
    for (int n = 0; n < m; ++n) {
      const MotionalMode& mode = fit.modes[static_cast<std::size_t>(n)];
      os << (n ? "," : "") << " f = " << mode.f0_hz << " +- " << s.params[3 + 3 * n].sigma
         << " Hz (Q " << mode.q << ", Rp " << mode.rp_ohm << " ohm)";
    }
    os << "; chi2/dof = " << s.chi2_per_dof << " (dof " << s.dof << ")";
  }
  s.message = os.str();
  candidate->usable = s.usable;
  candidate->message = s.message;
  return s;
}

}  // namespace

std::complex<double> MultiModeImpedance::At(double f_hz) const {
  Cplx z;
  std::vector<Cplx> dz;
  if (modes.empty()) return Cplx(r_ohm, 2.0 * std::numbers::pi * f_hz * l_h);
  Evaluate(*this, f_hz, &z, &dz);
  return z;
}

bool ModesFitOptions::IsValid(std::string* why) const {
  if (!single.IsValid(why)) return false;
  if (max_modes < 1 || max_modes > 6) {
    if (why) *why = "max_modes must be in [1, 6]";
    return false;
  }
  return true;
}

MultiModeImpedance ModesFitSummary::Model() const {
  if (mode_count == 1) return FromSingle(fit);
  MultiModeImpedance m;
  auto value = [&](const std::string& name) {
    const FittedParameter* p = fit.Find(name);
    return p ? p->value : 0.0;
  };
  m.r_ohm = value("R_ohm");
  m.l_h = value("L_h");
  for (int n = 1; n <= mode_count; ++n) {
    const std::string k = std::to_string(n);
    m.modes.push_back({value("Rp" + k + "_ohm"), value("f" + k + "_hz"), value("Q" + k)});
  }
  return m;
}

ModesFitSummary FitMotionalModes(const Frf& z, const ModesFitOptions& options) {
  ModesFitSummary out;
  std::string why;
  if (!options.IsValid(&why)) {
    out.message = "invalid input: options: " + why;
    out.fit.termination = Termination::kInvalidInput;
    return out;
  }
  out.fit = FitMotionalResonance(z, options.single);
  ModeOrderCandidate one;
  one.modes = 1;
  one.usable = out.fit.usable;
  one.message = out.fit.message;
  if (!out.fit.usable) {
    out.message = "one-mode fit not usable: " + out.fit.message;
    out.candidates.push_back(one);
    return out;
  }
  const bool sigma_known = z.has_sigma();
  const double chi2_one_raw =
      sigma_known ? out.fit.chi2 : out.fit.estimated_sigma * out.fit.estimated_sigma * out.fit.dof;
  one.chi2 = chi2_one_raw;
  one.bic = Bic(chi2_one_raw, ParamCount(1), z.size(), sigma_known);
  out.candidates.push_back(one);
  out.usable = true;
  out.mode_count = 1;

  Data d{z.freq_hz, z.value, std::vector<double>(z.size(), std::numbers::sqrt2)};
  if (sigma_known)
    for (std::size_t k = 0; k < z.size(); ++k) d.scale[k] = std::numbers::sqrt2 / z.sigma[k];
  const bool auto_range = options.single.f0_min_hz == 0.0 && options.single.f0_max_hz == 0.0;
  const double f0_lo = auto_range ? z.freq_hz.front() : options.single.f0_min_hz;
  const double f0_hi = auto_range ? z.freq_hz.back() : options.single.f0_max_hz;

  MultiModeImpedance current = FromSingle(out.fit);
  std::ostringstream decision = MessageStream();
  decision << "1 mode";
  for (int m = 2; m <= options.max_modes; ++m) {
    ModeOrderCandidate cand;
    FitSummary next = AddMode(d, current, options, f0_lo, f0_hi, sigma_known, &cand);
    const double bic_prev = out.candidates.back().bic;
    out.candidates.push_back(cand);
    if (!cand.usable) {
      decision << "; " << m << " modes rejected: " << cand.message;
      break;
    }
    if (!(cand.bic < bic_prev)) {
      decision << "; " << m << " modes rejected: BIC " << cand.bic << " not below " << bic_prev;
      break;
    }
    decision.str("");
    decision << m << " modes (BIC " << cand.bic << " < " << bic_prev << ")";
    out.fit = std::move(next);
    out.mode_count = m;
    current = out.Model();
  }
  out.message = "model order: " + decision.str() + ". " + out.fit.message;
  return out;
}

}  // namespace eol::analysis
