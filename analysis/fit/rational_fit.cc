#include "analysis/fit/rational_fit.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <locale>
#include <numbers>
#include <sstream>

#include "analysis/fit/least_squares.h"
#include "analysis/text.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

// Where the free coefficients sit: numerator powers first, then denominator powers, each
// ascending, the fixed constant left out.
struct Layout {
  int nb = 0;
  int na = 0;
  bool fix_numerator = true;

  int first_num() const { return fix_numerator ? 1 : 0; }
  int first_den() const { return fix_numerator ? 0 : 1; }
  int num_free() const { return nb + 1 - first_num(); }
  int free() const { return nb + na + 1; }

  void Expand(const Eigen::VectorXd& theta, Eigen::VectorXd* n, Eigen::VectorXd* d) const {
    *n = Eigen::VectorXd::Zero(nb + 1);
    *d = Eigen::VectorXd::Zero(na + 1);
    if (fix_numerator)
      (*n)[0] = 1.0;
    else
      (*d)[0] = 1.0;
    for (int i = first_num(); i <= nb; ++i) (*n)[i] = theta[i - first_num()];
    for (int i = first_den(); i <= na; ++i) (*d)[i] = theta[num_free() + i - first_den()];
  }
  // Power of s of free coefficient c, and whether it is in the numerator.
  int Power(int c) const { return c < num_free() ? c + first_num() : c - num_free() + first_den(); }
  bool InNumerator(int c) const { return c < num_free(); }
};

Cplx Horner(const Eigen::VectorXd& c, Cplx x) {
  Cplx y = 0.0;
  for (Eigen::Index i = c.size() - 1; i >= 0; --i) y = y * x + c[i];
  return y;
}

RationalFitSummary Invalid(const std::string& why) {
  RationalFitSummary s;
  s.termination = Termination::kInvalidInput;
  s.message = "invalid input: " + why;
  return s;
}

// The lines on the scaled axis x = j w / w_ref (w_ref the geometric centre of the band) with
// their weights sqrt(2) / sigma (sigma 1 when unknown), and the values to fit.
struct Lines {
  double w_ref = 1.0;
  std::vector<Cplx> x;
  std::vector<double> scale;
  const std::vector<Cplx>& value;
  std::size_t size() const { return x.size(); }
  Eigen::Index rows() const { return static_cast<Eigen::Index>(2 * x.size()); }
};

Lines ScaleLines(const std::vector<double>& freq_hz, const std::vector<Cplx>& value,
                 const std::vector<double>& sigma) {
  const std::size_t k_lines = freq_hz.size();
  double f_min = freq_hz[0], f_max = freq_hz[0];
  for (double f : freq_hz) {
    f_min = std::min(f_min, f);
    f_max = std::max(f_max, f);
  }
  Lines lines{2.0 * std::numbers::pi * std::sqrt(f_min * f_max), std::vector<Cplx>(k_lines),
              std::vector<double>(k_lines), value};
  for (std::size_t k = 0; k < k_lines; ++k) {
    lines.x[k] = Cplx(0.0, 2.0 * std::numbers::pi * freq_hz[k] / lines.w_ref);
    lines.scale[k] = std::numbers::sqrt2 / (sigma.empty() ? 1.0 : sigma[k]);
  }
  return lines;
}

// Why the options or the lines cannot be fitted; empty when they can.
std::string InputProblem(const std::vector<double>& freq_hz, const std::vector<Cplx>& value,
                         const std::vector<double>& sigma, const RationalFitOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) return "options: " + why;
  const std::size_t k_lines = freq_hz.size();
  if (value.size() != k_lines || (!sigma.empty() && sigma.size() != k_lines))
    return "frequency, value and sigma must have the same length";
  const int p = options.numerator_order + options.denominator_order + 1;  // Layout::free()
  if (static_cast<int>(2 * k_lines) < 2 * p)
    return std::to_string(k_lines) + " lines for " + std::to_string(p) +
           " coefficients (need 2 real values per coefficient)";
  for (std::size_t k = 0; k < k_lines; ++k) {
    if (!(std::isfinite(freq_hz[k]) && freq_hz[k] > 0.0) || !std::isfinite(value[k].real()) ||
        !std::isfinite(value[k].imag()) ||
        (!sigma.empty() && !(std::isfinite(sigma[k]) && sigma[k] > 0.0)))
      return "line " + std::to_string(k) + " is not finite or not positive";
  }
  return "";
}

// Levy, then Sanathanan-Koerner: min sum |scale (N - H D)|^2 / |D_prev|^2, linear in theta.
// *steps is the last step taken.
Eigen::VectorXd SanathananKoerner(const Layout& lay, const Lines& lines, int iterations,
                                  int* steps) {
  const int p = lay.free();
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(p);
  Eigen::VectorXd n, d;
  const Eigen::Index rows = lines.rows();
  for (int it = 0; it <= iterations; ++it) {
    lay.Expand(theta, &n, &d);
    Eigen::MatrixXd a(rows, p);
    Eigen::VectorXd rhs(rows);
    for (std::size_t k = 0; k < lines.size(); ++k) {
      const Cplx& x = lines.x[k];
      const double w = lines.scale[k] / (it == 0 ? 1.0 : std::abs(Horner(d, x)));
      const Cplx fixed = lay.fix_numerator ? Cplx(1.0) : -lines.value[k];
      const auto r = static_cast<Eigen::Index>(2 * k);
      for (int c = 0; c < p; ++c) {
        const Cplx xp = std::pow(x, lay.Power(c));
        const Cplx e = (lay.InNumerator(c) ? xp : -lines.value[k] * xp) * w;
        a(r, c) = e.real();
        a(r + 1, c) = e.imag();
      }
      rhs[r] = -(fixed * w).real();
      rhs[r + 1] = -(fixed * w).imag();
    }
    const Eigen::VectorXd col = a.colwise().norm().transpose().cwiseMax(1e-300);
    const Eigen::VectorXd next =
        (a * col.cwiseInverse().asDiagonal()).colPivHouseholderQr().solve(rhs).cwiseQuotient(col);
    const double change = (next - theta).norm() / std::max(next.norm(), 1e-300);
    theta = next;
    *steps = it;
    if (it > 0 && change < 1e-13) break;
  }
  return theta;
}

// The weighted output error (N / D - H) sqrt(2) / sigma as real rows, and its Jacobian in
// theta.
void OutputError(const Layout& lay, const Lines& lines, const Eigen::VectorXd& th,
                 Eigen::VectorXd* r) {
  Eigen::VectorXd nn, dd;
  lay.Expand(th, &nn, &dd);
  r->resize(lines.rows());
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const Cplx e =
        (Horner(nn, lines.x[k]) / Horner(dd, lines.x[k]) - lines.value[k]) * lines.scale[k];
    (*r)[static_cast<Eigen::Index>(2 * k)] = e.real();
    (*r)[static_cast<Eigen::Index>(2 * k + 1)] = e.imag();
  }
}

void OutputErrorJacobian(const Layout& lay, const Lines& lines, const Eigen::VectorXd& th,
                         Eigen::MatrixXd* j) {
  const int p = lay.free();
  Eigen::VectorXd nn, dd;
  lay.Expand(th, &nn, &dd);
  j->resize(lines.rows(), p);
  for (std::size_t k = 0; k < lines.size(); ++k) {
    const Cplx num = Horner(nn, lines.x[k]), den = Horner(dd, lines.x[k]);
    for (int c = 0; c < p; ++c) {
      const Cplx xp = std::pow(lines.x[k], lay.Power(c));
      const Cplx e = (lay.InNumerator(c) ? xp / den : -num * xp / (den * den)) * lines.scale[k];
      (*j)(static_cast<Eigen::Index>(2 * k), c) = e.real();
      (*j)(static_cast<Eigen::Index>(2 * k + 1), c) = e.imag();
    }
  }
}

// chi2 (the noise estimated from the residual without sigma), the coefficients in s (rad/s)
// with their covariance; returns whether the covariance is finite.
bool FillStatistics(const Layout& lay, const Lines& lines, const Eigen::VectorXd& theta,
                    RationalFitSummary* s) {
  const int p = lay.free();
  Eigen::VectorXd r;
  Eigen::MatrixXd jac;
  OutputError(lay, lines, theta, &r);
  OutputErrorJacobian(lay, lines, theta, &jac);
  s->dof = static_cast<int>(lines.rows()) - p;
  const double chi2_raw = r.squaredNorm();
  const double noise_var = s->sigma_estimated && s->dof > 0 ? chi2_raw / s->dof : 1.0;
  s->chi2 = noise_var > 0.0 ? chi2_raw / noise_var : chi2_raw;
  s->chi2_per_dof = s->dof > 0 ? s->chi2 / s->dof : std::numeric_limits<double>::quiet_NaN();

  // Back to s in rad/s: a coefficient of s^i scales by w_ref^-i.
  Eigen::VectorXd to_physical(p);
  for (int c = 0; c < p; ++c) to_physical[c] = std::pow(lines.w_ref, -lay.Power(c));
  lay.Expand(theta.cwiseProduct(to_physical), &s->numerator, &s->denominator);
  Eigen::MatrixXd inverse;
  const bool covariance_ok =
      r.allFinite() && jac.allFinite() && InvertInformation(jac.transpose() * jac, &inverse);
  if (covariance_ok)
    s->covariance = to_physical.asDiagonal() * (inverse * noise_var) * to_physical.asDiagonal();
  for (int c = 0; c < p; ++c) {
    FittedParameter fp;
    fp.name = std::string(lay.InNumerator(c) ? "n" : "d") + std::to_string(lay.Power(c));
    fp.unit = "s^" + std::to_string(lay.Power(c));
    fp.value = theta[c] * to_physical[c];
    fp.sigma =
        covariance_ok ? std::sqrt(s->covariance(c, c)) : std::numeric_limits<double>::quiet_NaN();
    s->coefficients.push_back(fp);
  }
  return covariance_ok;
}

}  // namespace

bool RationalFitOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (numerator_order < 0 || denominator_order < 0 || numerator_order + denominator_order < 1)
    return fail("numerator_order and denominator_order must be >= 0, with a sum >= 1");
  if (sk_iterations < 0) return fail("sk_iterations must not be negative");
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  return true;
}

Cplx RationalFitSummary::At(double f_hz) const {
  const Cplx s(0.0, 2.0 * std::numbers::pi * f_hz);
  return Horner(numerator, s) / Horner(denominator, s);
}

double RationalFitSummary::Coefficient(const std::string& name) const {
  if (name.size() < 2) return std::numeric_limits<double>::quiet_NaN();
  const int i = std::atoi(name.c_str() + 1);
  const Eigen::VectorXd& c = name[0] == 'n' ? numerator : denominator;
  if ((name[0] != 'n' && name[0] != 'd') || i < 0 || i >= c.size())
    return std::numeric_limits<double>::quiet_NaN();
  return c[i];
}

RationalFitSummary FitRational(const std::vector<double>& freq_hz, const std::vector<Cplx>& value,
                               const std::vector<double>& sigma,
                               const RationalFitOptions& options) {
  if (const std::string why = InputProblem(freq_hz, value, sigma, options); !why.empty())
    return Invalid(why);
  const Layout lay{options.numerator_order, options.denominator_order,
                   options.normalization == RationalNormalization::kNumeratorConstant};
  const Lines lines = ScaleLines(freq_hz, value, sigma);

  RationalFitSummary s;
  s.sigma_estimated = sigma.empty();
  Eigen::VectorXd theta = SanathananKoerner(lay, lines, options.sk_iterations, &s.sk_iterations);
  LeastSquaresProblem problem;
  problem.parameters = lay.free();
  problem.residuals = static_cast<int>(lines.rows());
  problem.residual = [&](const Eigen::VectorXd& th, Eigen::VectorXd* r) {
    OutputError(lay, lines, th, r);
  };
  problem.jacobian = [&](const Eigen::VectorXd& th, Eigen::MatrixXd* j) {
    OutputErrorJacobian(lay, lines, th, j);
  };
  LeastSquaresSettings settings;
  settings.max_iterations = options.max_iterations;
  const LeastSquaresOutcome lm = MinimizeLeastSquares(problem, &theta, settings);
  s.iterations = lm.iterations;
  s.termination = lm.termination;
  const bool covariance_ok = FillStatistics(lay, lines, theta, &s);

  std::ostringstream os = MessageStream();
  if (!lm.converged) {
    os << "Levenberg-Marquardt on the output error did not converge (" << ToString(lm.termination)
       << " after " << lm.iterations << " iterations, MINPACK status " << lm.minpack_status << ")";
  } else if (!covariance_ok) {
    os << "the coefficients are not determined by the data (singular Jacobian)";
  } else {
    s.usable = true;
    os << "output-error fit of order " << options.numerator_order << "/"
       << options.denominator_order << " converged in " << lm.iterations << " iterations ("
       << s.sk_iterations << " Sanathanan-Koerner steps first), chi2/dof = " << s.chi2_per_dof;
    if (s.sigma_estimated) os << " (no sigma: noise estimated from the residual)";
  }
  s.message = os.str();
  return s;
}

}  // namespace eol::analysis
