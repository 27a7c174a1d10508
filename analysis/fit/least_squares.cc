#include "analysis/fit/least_squares.h"

#include <unsupported/Eigen/NonLinearOptimization>

#include "analysis/enum_names.h"

namespace eol::analysis {

const char* ToString(Termination t) {
  switch (t) {
    case Termination::kConverged:
      return "converged";
    case Termination::kMaxIterations:
      return "max_iterations";
    case Termination::kFailed:
      return "failed";
    case Termination::kInvalidInput:
      return "invalid_input";
  }
  return "unknown";
}

std::optional<Termination> ParseTermination(std::string_view name) {
  return ParseEnum(name, kAllTerminations);
}

namespace {

constexpr double kRejectResidual = 1e100;

struct Functor {
  using Scalar = double;
  enum { InputsAtCompileTime = Eigen::Dynamic, ValuesAtCompileTime = Eigen::Dynamic };
  using InputType = Eigen::VectorXd;
  using ValueType = Eigen::VectorXd;
  using JacobianType = Eigen::MatrixXd;

  const LeastSquaresProblem& p;

  int inputs() const { return p.parameters; }
  int values() const { return p.residuals; }

  int operator()(const Eigen::VectorXd& x, Eigen::VectorXd& r) const {
    if (!x.allFinite()) {
      r.setConstant(p.residuals, kRejectResidual);
      return 0;
    }
    p.residual(x, &r);
    if (r.size() != p.residuals || !r.allFinite()) r.setConstant(p.residuals, kRejectResidual);
    return 0;
  }
  int df(const Eigen::VectorXd& x, Eigen::MatrixXd& j) const {
    p.jacobian(x, &j);
    return j.allFinite() ? 0 : -1;
  }
};

}  // namespace

LeastSquaresOutcome MinimizeLeastSquares(const LeastSquaresProblem& problem, Eigen::VectorXd* x,
                                         const LeastSquaresSettings& settings) {
  Functor functor{problem};
  Eigen::LevenbergMarquardt<Functor> lm(functor);
  lm.parameters.ftol = settings.ftol;
  lm.parameters.xtol = settings.xtol;
  lm.parameters.maxfev = 20 * (settings.max_iterations + 10);
  using Eigen::LevenbergMarquardtSpace::Status;
  Status status = lm.minimizeInit(*x);
  if (status == Status::NotStarted) {
    do {
      status = lm.minimizeOneStep(*x);
    } while (status == Status::Running && lm.iter - 1 < settings.max_iterations);
  }
  LeastSquaresOutcome out;
  out.iterations = static_cast<int>(lm.iter > 0 ? lm.iter - 1 : 0);
  out.minpack_status = static_cast<int>(status);
  switch (status) {
    case Status::RelativeReductionTooSmall:
    case Status::RelativeErrorTooSmall:
    case Status::RelativeErrorAndReductionTooSmall:
    case Status::CosinusTooSmall:
    // Tolerances below machine precision: no further improvement is possible, a solution.
    case Status::FtolTooSmall:
    case Status::XtolTooSmall:
    case Status::GtolTooSmall:
      out.converged = true;
      out.termination = Termination::kConverged;
      break;
    case Status::Running:
    case Status::TooManyFunctionEvaluation:
      out.termination = Termination::kMaxIterations;
      break;
    default:
      out.termination = Termination::kFailed;
      break;
  }
  return out;
}

bool InvertInformation(const Eigen::MatrixXd& info, Eigen::MatrixXd* inverse) {
  if (info.rows() == 0 || info.rows() != info.cols() || !info.allFinite()) return false;
  const Eigen::VectorXd d = info.diagonal();
  if (!(d.array() > 0.0).all()) return false;
  const Eigen::VectorXd s = d.array().rsqrt().matrix();
  const Eigen::MatrixXd scaled = s.asDiagonal() * info * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(scaled);
  if (eig.info() != Eigen::Success) return false;
  const Eigen::VectorXd lambda = eig.eigenvalues();
  if (!(lambda[0] > 1e-13 * lambda[lambda.size() - 1])) return false;
  const Eigen::MatrixXd result =
      s.asDiagonal() *
      (eig.eigenvectors() * lambda.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose()) *
      s.asDiagonal();
  if (!result.allFinite()) return false;
  *inverse = result;
  return true;
}

}  // namespace eol::analysis
