#include "analysis/fit/paper_route.h"

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;
using Mapping = std::function<Eigen::VectorXd(const Eigen::VectorXd&)>;

struct Output {
  const char* name;
  const char* unit;
};

PaperRouteSummary Invalid(const std::string& why) {
  PaperRouteSummary s;
  s.rational.termination = Termination::kInvalidInput;
  s.message = "invalid input: " + why;
  return s;
}

Eigen::VectorXd Values(const RationalFitSummary& fit) {
  Eigen::VectorXd c(static_cast<Eigen::Index>(fit.coefficients.size()));
  for (std::size_t i = 0; i < fit.coefficients.size(); ++i)
    c[static_cast<Eigen::Index>(i)] = fit.coefficients[i].value;
  return c;
}

// d mapping / d coefficients by central differences (relative step 1e-6).
Eigen::MatrixXd Gradient(const Mapping& g, const Eigen::VectorXd& c) {
  const Eigen::VectorXd g0 = g(c);
  Eigen::MatrixXd jac(g0.size(), c.size());
  for (Eigen::Index i = 0; i < c.size(); ++i) {
    const double h = 1e-6 * (c[i] != 0.0 ? std::abs(c[i]) : 1.0);
    Eigen::VectorXd up = c, down = c;
    up[i] += h;
    down[i] -= h;
    jac.col(i) = (g(up) - g(down)) / (2.0 * h);
  }
  return jac;
}

// Fills s.estimates from the mapping of the fitted coefficients, with propagated sigmas.
void Propagate(const Mapping& g, const std::vector<Output>& outputs, PaperRouteSummary* s) {
  const Eigen::VectorXd c = Values(s->rational);
  const Eigen::VectorXd v = g(c);
  Eigen::VectorXd sigma = Eigen::VectorXd::Constant(v.size(), std::nan(""));
  if (s->rational.covariance.size() > 0) {
    const Eigen::MatrixXd jac = Gradient(g, c);
    sigma = (jac * s->rational.covariance * jac.transpose()).diagonal().cwiseSqrt();
  }
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    s->estimates.push_back({outputs[i].name, outputs[i].unit, v[k], sigma[k]});
  }
}

void Finish(PaperRouteSummary* s) {
  bool finite = true;
  for (const FittedParameter& p : s->estimates) finite = finite && std::isfinite(p.value);
  s->usable = s->rational.usable && finite;
  if (!s->rational.usable)
    s->message = "rational fit not usable: " + s->rational.message;
  else if (!finite)
    s->message =
        "the coefficients do not map to physical parameters (negative radicand in "
        "eq. 28, or a zero coefficient): the data do not follow the model";
  else
    s->message = s->rational.message;
}

}  // namespace

const FittedParameter* PaperRouteSummary::Find(const std::string& name) const {
  for (const FittedParameter& p : estimates)
    if (p.name == name) return &p;
  return nullptr;
}

PaperRouteSummary FitPaperAdmittance(const Frf& z, double inertia_kg_m2,
                                     const RationalFitOptions& options) {
  std::string why;
  if (!z.Validate(&why)) return Invalid(why);
  if (z.quantity != Quantity::kImpedanceOhm)
    return Invalid(std::string("quantity is ") + ToString(z.quantity) + ", need impedance");
  if (!(std::isfinite(inertia_kg_m2) && inertia_kg_m2 > 0.0))
    return Invalid("the given J_r must be finite and positive");
  std::vector<Cplx> y(z.size());
  std::vector<double> sigma_y;
  for (std::size_t k = 0; k < z.size(); ++k) {
    y[k] = 1.0 / z.value[k];
    if (z.has_sigma()) sigma_y.push_back(z.sigma[k] / std::norm(z.value[k]));
  }
  RationalFitOptions o = options;
  o.numerator_order = 2;
  o.denominator_order = 3;
  o.normalization = RationalNormalization::kNumeratorConstant;
  PaperRouteSummary s;
  s.rational = FitRational(z.freq_hz, y, sigma_y, o);
  if (s.rational.coefficients.size() != 6) {
    s.message = "rational fit not usable: " + s.rational.message;
    return s;
  }
  // Free coefficients in order n1, n2, d0, d1, d2, d3 = B2, B3, A1, A2, A3, A4.
  auto coefficients = [](const Eigen::VectorXd& c) {
    return AdmittanceCoefficients{c[0], c[1], c[2], c[3], c[4], c[5]};
  };
  const Mapping g = [&](const Eigen::VectorXd& c) {
    const PmsmParams p = FromAdmittanceCoefficients(coefficients(c), inertia_kg_m2);
    const MotionalImpedance m = ToMotional(p);
    Eigen::VectorXd v(8);
    v << p.r_ohm, p.l_h, p.transmission_nm_per_a, p.compliance_rad_per_nm, p.damping_nms_per_rad,
        m.f0_hz, m.q, m.rp_ohm;
    return v;
  };
  Propagate(g,
            {{"R_ohm", "ohm"},
             {"L_h", "H"},
             {"T_nm_per_a", "N m/A"},
             {"Cm_rad_per_nm", "rad/(N m)"},
             {"Rm_nms_per_rad", "N m s/rad"},
             {"f0_hz", "Hz"},
             {"Q", "1"},
             {"Rp_ohm", "ohm"}},
            &s);
  const Eigen::VectorXd c = Values(s.rational);
  s.params = FromAdmittanceCoefficients(coefficients(c), inertia_kg_m2);
  s.constraint = AdmittanceConstraint(coefficients(c));
  if (s.rational.covariance.size() > 0) {
    const Mapping h = [&](const Eigen::VectorXd& x) {
      return Eigen::VectorXd::Constant(1, AdmittanceConstraint(coefficients(x)));
    };
    const Eigen::MatrixXd jac = Gradient(h, c);
    s.constraint_sigma = std::sqrt((jac * s.rational.covariance * jac.transpose())(0, 0));
    s.constraint_z = s.constraint / s.constraint_sigma;
  }
  Finish(&s);
  return s;
}

PaperRouteSummary FitPaperMechanical(const Frf& mobility, double inertia_kg_m2,
                                     const RationalFitOptions& options) {
  std::string why;
  if (!mobility.Validate(&why)) return Invalid(why);
  if (mobility.quantity != Quantity::kMobility)
    return Invalid(std::string("quantity is ") + ToString(mobility.quantity) +
                   ", need mobility (angular velocity per current)");
  if (!(std::isfinite(inertia_kg_m2) && inertia_kg_m2 > 0.0))
    return Invalid("the given J_r must be finite and positive");
  std::vector<Cplx> h(mobility.size());
  std::vector<double> sigma_h;
  for (std::size_t k = 0; k < mobility.size(); ++k) {
    const double w = 2.0 * std::numbers::pi * mobility.freq_hz[k];
    h[k] = Cplx(0.0, w) * mobility.value[k];
    if (mobility.has_sigma()) sigma_h.push_back(w * mobility.sigma[k]);
  }
  RationalFitOptions o = options;
  o.numerator_order = 2;
  o.denominator_order = 2;
  o.normalization = RationalNormalization::kDenominatorConstant;
  PaperRouteSummary s;
  s.rational = FitRational(mobility.freq_hz, h, sigma_h, o);
  if (s.rational.coefficients.size() != 5) {
    s.message = "rational fit not usable: " + s.rational.message;
    return s;
  }
  // Free coefficients in order n0, n1, n2, d1, d2 = D1, D2, D3, C2, C3.
  auto coefficients = [](const Eigen::VectorXd& c) {
    return MechanicalCoefficients{c[0], c[1], c[2], c[3], c[4]};
  };
  const Mapping g = [&](const Eigen::VectorXd& c) {
    const MechanicalCoefficients mc = coefficients(c);
    const PmsmParams p = FromMechanicalCoefficients(mc, inertia_kg_m2);
    Eigen::VectorXd v(5);
    v << p.transmission_nm_per_a, p.compliance_rad_per_nm, p.damping_nms_per_rad,
        1.0 / (2.0 * std::numbers::pi * std::sqrt(mc.c3)), std::sqrt(mc.c3) / mc.c2;
    return v;
  };
  Propagate(g,
            {{"T_nm_per_a", "N m/A"},
             {"Cm_rad_per_nm", "rad/(N m)"},
             {"Rm_nms_per_rad", "N m s/rad"},
             {"f0_hz", "Hz"},
             {"Q", "1"}},
            &s);
  s.params = FromMechanicalCoefficients(coefficients(Values(s.rational)), inertia_kg_m2);
  Finish(&s);
  return s;
}

}  // namespace eol::analysis
