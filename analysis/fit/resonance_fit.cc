#include "analysis/fit/resonance_fit.h"

#include <algorithm>
#include <cmath>
#include <complex>
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

constexpr int kMinLinesPerParam = 2;
constexpr int kRefineSteps = 21;   // points per axis of each local refinement grid
constexpr int kRefinePasses = 2;   // successive refinements around the best cell
constexpr double kLmFtol = 1e-12;  // MINPACK relative reduction of chi2
constexpr double kLmXtol = 1e-10;  // MINPACK relative step in scaled theta

// R, L, Rp of the weighted linear least-squares solution at one (f0, Q) grid point.
struct GridPoint {
  bool ok = false;  // solved and R, L, Rp > 0
  double f0_hz = 0.0;
  double q = 0.0;
  double r_ohm = 0.0;
  double l_h = 0.0;
  double rp_ohm = 0.0;
  double chi2 = std::numeric_limits<double>::infinity();
};

// Variable projection over (f0, Q). For fixed f0, Q the model is linear in (R, L, Rp) with
// complex basis 1, j w, 1/D, and 1/D = g (1 - j Q x), g = 1 / (1 + Q^2 x^2). With weights
// c_k = s_k^2 = 2 / sigma_k^2, v_k = w_k / w_ref (L' = L w_ref keeps the system scaled) and
// Z_k = a_k + j b_k, the real normal equations are
//   [ sum c      0            S0    ] [R ]   [ sum c a       ]
//   [ 0          sum c v^2   -Q S1  ] [L'] = [ sum c v b     ]
//   [ S0        -Q S1         S0    ] [Rp]   [ S2 - Q S3     ]
// with S0 = sum c g, S1 = sum c v x g, S2 = sum c a g, S3 = sum c x b g, solved by eliminating
// R and L' (Schur complement). chi2 = sum c |Z|^2 - p . rhs at the solution.
class VarProGrid {
 public:
  VarProGrid(const std::vector<double>& freq_hz, const std::vector<Cplx>& z,
             const std::vector<double>& scale)
      : f_(freq_hz) {
    const std::size_t n = f_.size();
    w_ref_ = 2.0 * std::numbers::pi * f_.back();
    c_.resize(n);
    v_.resize(n);
    a_.resize(n);
    b_.resize(n);
    for (std::size_t k = 0; k < n; ++k) {
      c_[k] = scale[k] * scale[k];
      v_[k] = 2.0 * std::numbers::pi * f_[k] / w_ref_;
      a_[k] = z[k].real();
      b_[k] = z[k].imag();
      n11_ += c_[k];
      n22_ += c_[k] * v_[k] * v_[k];
      rhs1_ += c_[k] * a_[k];
      rhs2_ += c_[k] * v_[k] * b_[k];
      zz_ += c_[k] * std::norm(z[k]);
    }
  }

  // Solves every Q of `qs` at f0; out[i] belongs to qs[i].
  void Row(double f0_hz, const std::vector<double>& qs, std::vector<GridPoint>* out) {
    const std::size_t n = f_.size();
    const std::size_t nq = qs.size();
    q2_.resize(nq);
    s0_.assign(nq, 0.0);
    s1_.assign(nq, 0.0);
    s2_.assign(nq, 0.0);
    s3_.assign(nq, 0.0);
    for (std::size_t i = 0; i < nq; ++i) q2_[i] = qs[i] * qs[i];
    // Lines outer, Q inner: independent accumulators per Q let the compiler vectorise.
    for (std::size_t k = 0; k < n; ++k) {
      const double x = f_[k] / f0_hz - f0_hz / f_[k];
      const double x2 = x * x;
      const double c0 = c_[k];
      const double c1 = c_[k] * v_[k] * x;
      const double c2 = c_[k] * a_[k];
      const double c3 = c_[k] * x * b_[k];
      for (std::size_t i = 0; i < nq; ++i) {
        const double g = 1.0 / (1.0 + q2_[i] * x2);
        s0_[i] += c0 * g;
        s1_[i] += c1 * g;
        s2_[i] += c2 * g;
        s3_[i] += c3 * g;
      }
    }
    out->resize(nq);
    for (std::size_t i = 0; i < nq; ++i) {
      GridPoint& p = (*out)[i];
      p = GridPoint{};
      p.f0_hz = f0_hz;
      p.q = qs[i];
      const double s0 = s0_[i];
      const double n23 = -qs[i] * s1_[i];
      const double rhs3 = s2_[i] - qs[i] * s3_[i];
      const double schur = s0 - s0 * s0 / n11_ - n23 * n23 / n22_;
      // The peak column is (numerically) a combination of the R and L columns: no peak here.
      if (!(schur > 1e-12 * s0)) continue;
      const double rp = (rhs3 - s0 * rhs1_ / n11_ - n23 * rhs2_ / n22_) / schur;
      const double r = (rhs1_ - s0 * rp) / n11_;
      const double l_scaled = (rhs2_ - n23 * rp) / n22_;
      if (!(r > 0.0 && l_scaled > 0.0 && rp > 0.0)) continue;
      p.ok = true;
      p.r_ohm = r;
      p.l_h = l_scaled / w_ref_;
      p.rp_ohm = rp;
      p.chi2 = zz_ - (r * rhs1_ + l_scaled * rhs2_ + rp * rhs3);
    }
  }

  // Best valid point over the grid f0s x qs; *best_i, *best_j are its indices.
  GridPoint Search(const std::vector<double>& f0s, const std::vector<double>& qs, int* best_i,
                   int* best_j) {
    GridPoint best;
    std::vector<GridPoint> row;
    for (std::size_t i = 0; i < f0s.size(); ++i) {
      Row(f0s[i], qs, &row);
      for (std::size_t j = 0; j < row.size(); ++j) {
        if (row[j].ok && row[j].chi2 < best.chi2) {
          best = row[j];
          *best_i = static_cast<int>(i);
          *best_j = static_cast<int>(j);
        }
      }
    }
    return best;
  }

 private:
  const std::vector<double>& f_;
  std::vector<double> c_, v_, a_, b_;
  double w_ref_ = 1.0;
  double n11_ = 0.0, n22_ = 0.0, rhs1_ = 0.0, rhs2_ = 0.0, zz_ = 0.0;
  std::vector<double> q2_, s0_, s1_, s2_, s3_;
};

FitSummary Invalid(const std::string& why) {
  FitSummary s;
  s.usable = false;
  s.termination = Termination::kInvalidInput;
  s.message = "invalid input: " + why;
  return s;
}

// The f0 search range: the options' or, when both are 0, the data's band.
struct F0Range {
  double lo = 0.0, hi = 0.0;
};

F0Range SearchRange(const Frf& z, const ResonanceFitOptions& options) {
  const bool auto_range = options.f0_min_hz == 0.0 && options.f0_max_hz == 0.0;
  return {auto_range ? z.freq_hz.front() : options.f0_min_hz,
          auto_range ? z.freq_hz.back() : options.f0_max_hz};
}

// Why the options or the data cannot be fitted; empty when they can.
std::string InputProblem(const Frf& z, const ResonanceFitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return "options: " + why;
  if (!z.Validate(&why)) return why;
  if (z.quantity != Quantity::kImpedanceOhm)
    return std::string("quantity is ") + ToString(z.quantity) + ", the fit needs " +
           ToString(Quantity::kImpedanceOhm);
  const std::size_t k_lines = z.size();
  const std::size_t min_lines = kMinLinesPerParam * kMotionalParamCount;
  if (k_lines < min_lines)
    return std::to_string(k_lines) + " lines, the fit needs at least " + std::to_string(min_lines) +
           " (2 per parameter)";
  const F0Range range = SearchRange(z, options);
  if (!(range.lo < z.freq_hz.back() && range.hi > z.freq_hz.front())) {
    std::ostringstream os = MessageStream();
    os << "f0 search range [" << range.lo << ", " << range.hi
       << "] Hz does not overlap the data band [" << z.freq_hz.front() << ", " << z.freq_hz.back()
       << "] Hz";
    return os.str();
  }
  if (!(range.hi > range.lo)) return "the data band is a single frequency";
  return "";
}

std::string NoResonance(const F0Range& range) {
  std::ostringstream os = MessageStream();
  os << "no resonance found between " << range.lo << " and " << range.hi << " Hz";
  return os.str();
}

// The start of the fit: the best point of a coarse (f0, Q) grid, then of local refinements
// around the best cell. Not ok when no grid point gives positive R, L and Rp.
GridPoint GridStart(const Frf& z, const std::vector<double>& scale,
                    const ResonanceFitOptions& options, const F0Range& range) {
  VarProGrid grid(z.freq_hz, z.value, scale);
  std::vector<double> f0s = LogSpace(range.lo, range.hi, options.grid_f0);
  std::vector<double> qs = LogSpace(options.q_min, options.q_max, options.grid_q);
  int bi = -1, bj = -1;
  GridPoint start = grid.Search(f0s, qs, &bi, &bj);
  if (!start.ok) return start;
  for (int pass = 0; pass < kRefinePasses; ++pass) {
    const double f_a = f0s[static_cast<std::size_t>(std::max(bi - 1, 0))];
    const double f_b =
        f0s[static_cast<std::size_t>(std::min(bi + 1, static_cast<int>(f0s.size()) - 1))];
    const double q_a = qs[static_cast<std::size_t>(std::max(bj - 1, 0))];
    const double q_b =
        qs[static_cast<std::size_t>(std::min(bj + 1, static_cast<int>(qs.size()) - 1))];
    f0s = LogSpace(f_a, f_b, kRefineSteps);
    qs = LogSpace(q_a, q_b, kRefineSteps);
    int ri = -1, rj = -1;
    const GridPoint refined = grid.Search(f0s, qs, &ri, &rj);
    if (!refined.ok || !(refined.chi2 < start.chi2)) break;
    start = refined;
    bi = ri;
    bj = rj;
  }
  return start;
}

// Levenberg-Marquardt in theta = ln p from the grid's start; *theta ends at the fit.
LeastSquaresOutcome MinimiseFromStart(const Frf& z, const std::vector<double>& scale,
                                      const GridPoint& start, int max_iterations,
                                      Eigen::VectorXd* theta) {
  MotionalImpedance p0;
  p0.r_ohm = start.r_ohm;
  p0.l_h = start.l_h;
  p0.rp_ohm = start.rp_ohm;
  p0.f0_hz = start.f0_hz;
  p0.q = start.q;
  *theta = ToLogParams(p0);
  LeastSquaresProblem problem;
  problem.parameters = kMotionalParamCount;
  problem.residuals = static_cast<int>(2 * z.freq_hz.size());
  problem.residual = [&](const Eigen::VectorXd& t, Eigen::VectorXd* r) {
    MotionalResidual(FromLogParams(t), z.freq_hz, z.value, scale, r);
  };
  problem.jacobian = [&](const Eigen::VectorXd& t, Eigen::MatrixXd* jacobian) {
    MotionalJacobian(FromLogParams(t), z.freq_hz, scale, jacobian);
  };
  LeastSquaresSettings settings;
  settings.max_iterations = max_iterations;
  settings.ftol = kLmFtol;
  settings.xtol = kLmXtol;
  return MinimizeLeastSquares(problem, theta, settings);
}

// chi2 (noise scale 1 with known sigma, estimated from the residual otherwise), the
// covariance and the parameters at `fit`; returns whether the covariance is finite.
bool FillStatistics(const Frf& z, const std::vector<double>& scale, const MotionalImpedance& fit,
                    FitSummary* s) {
  Eigen::VectorXd r;
  Eigen::MatrixXd jacobian;
  MotionalResidual(fit, z.freq_hz, z.value, scale, &r);
  MotionalJacobian(fit, z.freq_hz, scale, &jacobian);
  const double chi2_raw = r.squaredNorm();
  double noise_var = 1.0;
  if (s->sigma_estimated) {
    noise_var = chi2_raw / s->dof;
    s->estimated_sigma = std::sqrt(noise_var);
  }
  s->chi2 = noise_var > 0.0 ? chi2_raw / noise_var : chi2_raw;
  s->chi2_per_dof = s->chi2 / s->dof;

  MotionalMatrix c_log = MotionalMatrix::Constant(std::numeric_limits<double>::quiet_NaN());
  bool covariance_ok = false;
  if (r.allFinite() && jacobian.allFinite()) {
    const MotionalMatrix jtj = jacobian.transpose() * jacobian;
    MotionalMatrix inverse;
    if (InvertInformation(jtj, &inverse)) {
      c_log = inverse * noise_var;
      covariance_ok = c_log.allFinite();
    }
  }
  const MotionalMatrix c_nat = LogToNaturalCovariance(fit, c_log);
  const MotionalVector values = ToNaturalVector(fit);
  s->params.resize(kMotionalParamCount);
  for (int i = 0; i < kMotionalParamCount; ++i) {
    FittedParameter& p = s->params[static_cast<std::size_t>(i)];
    p.name = kMotionalParamNames[static_cast<std::size_t>(i)];
    p.unit = kMotionalParamUnits[static_cast<std::size_t>(i)];
    p.value = values[i];
    p.sigma = covariance_ok ? std::sqrt(c_nat(i, i)) : std::numeric_limits<double>::quiet_NaN();
  }
  if (covariance_ok) s->covariance = c_nat;
  return covariance_ok;
}

// Why the converged fit is not a resonance (not determined, at the search range's edge, no
// significant peak); empty when it is one.
std::string RejectFit(const FitSummary& s, const MotionalImpedance& fit, bool covariance_ok,
                      const ResonanceFitOptions& options, const F0Range& range) {
  std::ostringstream os = MessageStream();
  if (!covariance_ok || !ToNaturalVector(fit).allFinite()) {
    os << "covariance is not finite at f0 = " << fit.f0_hz
       << " Hz: the Jacobian is singular there, the parameters are not determined by the data";
    return os.str();
  }
  const double coarse_log_step = std::log(range.hi / range.lo) / (options.grid_f0 - 1);
  const double edge_lo = range.lo * std::exp(coarse_log_step);
  const double edge_hi = range.hi * std::exp(-coarse_log_step);
  if (!(fit.f0_hz >= edge_lo && fit.f0_hz <= edge_hi)) {
    os << NoResonance(range) << ": the fit ended at f0 = " << fit.f0_hz
       << " Hz, at or beyond the edge of the search range";
    return os.str();
  }
  const double rp_sigma = s.params[kParamRp].sigma;
  if (!(fit.rp_ohm >= options.min_rp_significance * rp_sigma)) {
    os << NoResonance(range) << ": the motional peak Rp = " << fit.rp_ohm << " +- " << rp_sigma
       << " ohm is below " << options.min_rp_significance << " standard deviations";
    return os.str();
  }
  return "";
}

// The message of a usable fit, with a warning when chi2/dof is well above 1.
std::string UsableMessage(const FitSummary& s, const MotionalImpedance& fit) {
  std::ostringstream os = MessageStream();
  os << "converged in " << s.iterations << " iterations: f0 = " << fit.f0_hz << " +- "
     << s.params[kParamF0].sigma << " Hz, Q = " << fit.q << " +- " << s.params[kParamQ].sigma
     << ", chi2/dof = " << s.chi2_per_dof << " (dof " << s.dof << ")";
  if (s.sigma_estimated) {
    os << ". The frequency response carried no sigma: noise estimated from the residual as "
       << s.estimated_sigma << " ohm per line (complex std), covariance scaled by it";
  } else if (s.chi2_per_dof > 1.0 + 5.0 * std::sqrt(2.0 / s.dof)) {
    os << ". chi2/dof is well above 1: the model does not explain the data within sigma "
          "(an unmodelled effect, analysis/README.md 5, or sigma underestimated)";
  }
  return os.str();
}

}  // namespace

bool ResonanceFitOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& msg) {
    if (why) *why = msg;
    return false;
  };
  const bool auto_range = f0_min_hz == 0.0 && f0_max_hz == 0.0;
  if (!auto_range && !(std::isfinite(f0_min_hz) && std::isfinite(f0_max_hz) && f0_min_hz > 0.0 &&
                       f0_max_hz > f0_min_hz))
    return fail(
        "f0_min_hz and f0_max_hz must both be 0 (the data's band) or satisfy "
        "0 < f0_min_hz < f0_max_hz");
  if (!(std::isfinite(q_min) && std::isfinite(q_max) && q_min > 0.0 && q_max > q_min))
    return fail("q_min and q_max must satisfy 0 < q_min < q_max");
  if (grid_f0 < 3) return fail("grid_f0 must be at least 3");
  if (grid_q < 2) return fail("grid_q must be at least 2");
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  if (!(min_rp_significance >= 0.0)) return fail("min_rp_significance must not be negative");
  return true;
}

const FittedParameter* FitSummary::Find(std::string_view name) const {
  for (const FittedParameter& p : params)
    if (p.name == name) return &p;
  return nullptr;
}

MotionalImpedance FitSummary::Model() const {
  auto value = [&](int i) {
    const FittedParameter* p = Find(kMotionalParamNames[static_cast<std::size_t>(i)]);
    return p ? p->value : 0.0;
  };
  MotionalImpedance m;
  m.r_ohm = value(kParamR);
  m.l_h = value(kParamL);
  m.rp_ohm = value(kParamRp);
  m.f0_hz = value(kParamF0);
  m.q = value(kParamQ);
  return m;
}

FitSummary FitMotionalResonance(const Frf& z, const ResonanceFitOptions& options) {
  if (const std::string why = InputProblem(z, options); !why.empty()) return Invalid(why);
  const std::size_t k_lines = z.size();
  const F0Range range = SearchRange(z, options);

  FitSummary s;
  s.sigma_estimated = !z.has_sigma();
  std::vector<double> scale(k_lines, std::numbers::sqrt2);
  if (z.has_sigma())
    for (std::size_t k = 0; k < k_lines; ++k) scale[k] = std::numbers::sqrt2 / z.sigma[k];
  s.dof = static_cast<int>(2 * k_lines) - kMotionalParamCount;

  const GridPoint start = GridStart(z, scale, options, range);
  if (!start.ok) {
    s.termination = Termination::kFailed;
    s.message = NoResonance(range) + ": no (f0, Q) grid point gives positive R, L and Rp";
    return s;
  }
  Eigen::VectorXd theta;
  const LeastSquaresOutcome lm = MinimiseFromStart(z, scale, start, options.max_iterations, &theta);
  s.iterations = lm.iterations;
  s.termination = lm.termination;
  const MotionalImpedance fit = FromLogParams(theta);
  const bool covariance_ok = FillStatistics(z, scale, fit, &s);

  if (!lm.converged) {
    std::ostringstream os = MessageStream();
    os << (s.termination == Termination::kMaxIterations ? "Levenberg-Marquardt did not converge in "
                                                        : "Levenberg-Marquardt failed after ")
       << s.iterations << " iterations (MINPACK status " << lm.minpack_status
       << "); started from the grid at f0 = " << start.f0_hz << " Hz, Q = " << start.q;
    s.message = os.str();
    return s;
  }
  s.message = RejectFit(s, fit, covariance_ok, options, range);
  if (!s.message.empty()) return s;
  s.usable = true;
  s.message = UsableMessage(s, fit);
  return s;
}

}  // namespace eol::analysis
