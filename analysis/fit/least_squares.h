// Levenberg-Marquardt (MINPACK, Eigen's unsupported NonLinearOptimization) for the fits that
// are not the single-mode resonance fit: the rational (output-error) fit, the multi-mode
// fit. The caller gives the residual r(x) and its Jacobian; a trial x whose residual is not
// finite is rejected (MINPACK sees a huge residual and shortens the step).
#pragma once

#include <Eigen/Dense>
#include <array>
#include <functional>
#include <optional>
#include <string_view>

namespace eol::analysis {

// How a fit ended. Stored in records and printed by the API as "converged", "max_iterations",
// "failed", "invalid_input" (ToString); those strings must not change.
enum class Termination {
  kConverged,      // a minimum within the tolerances
  kMaxIterations,  // stopped by the iteration (or evaluation) budget
  kFailed,         // the minimiser gave up (MINPACK status other than the above)
  kInvalidInput,   // no fit was attempted: bad data or options
};
inline constexpr std::array kAllTerminations = {Termination::kConverged,
                                                Termination::kMaxIterations, Termination::kFailed,
                                                Termination::kInvalidInput};
const char* ToString(Termination t);
std::optional<Termination> ParseTermination(std::string_view name);

struct LeastSquaresProblem {
  int parameters = 0;
  int residuals = 0;
  // Fills *r (resized by the callee to `residuals`).
  std::function<void(const Eigen::VectorXd& x, Eigen::VectorXd* r)> residual;
  // Fills *jacobian (residuals x parameters).
  std::function<void(const Eigen::VectorXd& x, Eigen::MatrixXd* jacobian)> jacobian;
};

struct LeastSquaresSettings {
  int max_iterations = 200;  // successful steps
  double ftol = 1e-12;       // relative reduction of |r|^2
  double xtol = 1e-10;       // relative step in scaled x
};

struct LeastSquaresOutcome {
  bool converged = false;
  Termination termination = Termination::kFailed;  // never kInvalidInput
  int iterations = 0;
  int minpack_status = 0;
};

// Minimises |r(x)|^2 from *x; *x holds the last accepted point.
LeastSquaresOutcome MinimizeLeastSquares(const LeastSquaresProblem& problem, Eigen::VectorXd* x,
                                         const LeastSquaresSettings& settings);

// Inverse of an information matrix F = J^T J (any size), computed on F scaled to unit
// diagonal. Returns false, leaving *inverse untouched, when F is not positive definite or its
// scaled smallest eigenvalue is below 1e-13 of the largest: the data do not determine every
// parameter. (motional_jacobian.h's fixed-size InvertInformation is this one.)
bool InvertInformation(const Eigen::MatrixXd& information, Eigen::MatrixXd* inverse);

}  // namespace eol::analysis
