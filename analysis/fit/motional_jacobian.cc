#include "analysis/fit/motional_jacobian.h"

#include <cmath>
#include <numbers>

#include "analysis/fit/least_squares.h"

namespace eol::analysis {

const std::array<const char*, kMotionalParamCount> kMotionalParamNames = {"R_ohm", "L_h", "Rp_ohm",
                                                                          "f0_hz", "Q"};
const std::array<const char*, kMotionalParamCount> kMotionalParamUnits = {"ohm", "H", "ohm", "Hz",
                                                                          "1"};

MotionalVector ToNaturalVector(const MotionalImpedance& p) {
  MotionalVector v;
  v << p.r_ohm, p.l_h, p.rp_ohm, p.f0_hz, p.q;
  return v;
}

MotionalImpedance FromNaturalVector(const MotionalVector& v) {
  MotionalImpedance p;
  p.r_ohm = v[kParamR];
  p.l_h = v[kParamL];
  p.rp_ohm = v[kParamRp];
  p.f0_hz = v[kParamF0];
  p.q = v[kParamQ];
  return p;
}

MotionalVector ToLogParams(const MotionalImpedance& p) {
  return ToNaturalVector(p).array().log().matrix();
}

MotionalImpedance FromLogParams(const MotionalVector& theta) {
  return FromNaturalVector(theta.array().exp().matrix());
}

MotionalPoint EvaluateMotional(const MotionalImpedance& p, double f_hz) {
  using Cplx = std::complex<double>;
  const Cplx j(0.0, 1.0);
  const double w = 2.0 * std::numbers::pi * f_hz;
  const double w_over_w0 = f_hz / p.f0_hz;
  const double x = w_over_w0 - 1.0 / w_over_w0;
  const double y = w_over_w0 + 1.0 / w_over_w0;
  const Cplx d(1.0, p.q * x);
  const Cplx zp = p.rp_ohm / d;
  const Cplx zp_over_d = zp / d;

  MotionalPoint out;
  out.z = p.r_ohm + j * (w * p.l_h) + zp;
  out.dz_dtheta[kParamR] = p.r_ohm;
  out.dz_dtheta[kParamL] = j * (w * p.l_h);
  out.dz_dtheta[kParamRp] = zp;
  out.dz_dtheta[kParamF0] = j * (p.q * y) * zp_over_d;
  out.dz_dtheta[kParamQ] = -j * (p.q * x) * zp_over_d;
  return out;
}

void MotionalResidual(const MotionalImpedance& p, const std::vector<double>& freq_hz,
                      const std::vector<std::complex<double>>& value,
                      const std::vector<double>& scale, Eigen::VectorXd* r) {
  const std::size_t n = freq_hz.size();
  r->resize(static_cast<Eigen::Index>(2 * n));
  for (std::size_t k = 0; k < n; ++k) {
    const std::complex<double> e = (EvaluateMotional(p, freq_hz[k]).z - value[k]) * scale[k];
    (*r)[static_cast<Eigen::Index>(2 * k)] = e.real();
    (*r)[static_cast<Eigen::Index>(2 * k + 1)] = e.imag();
  }
}

void MotionalJacobian(const MotionalImpedance& p, const std::vector<double>& freq_hz,
                      const std::vector<double>& scale, Eigen::MatrixXd* jacobian) {
  const std::size_t n = freq_hz.size();
  jacobian->resize(static_cast<Eigen::Index>(2 * n), kMotionalParamCount);
  for (std::size_t k = 0; k < n; ++k) {
    const MotionalPoint m = EvaluateMotional(p, freq_hz[k]);
    const auto row = static_cast<Eigen::Index>(2 * k);
    for (int i = 0; i < kMotionalParamCount; ++i) {
      const std::complex<double> d = m.dz_dtheta[static_cast<std::size_t>(i)] * scale[k];
      (*jacobian)(row, i) = d.real();
      (*jacobian)(row + 1, i) = d.imag();
    }
  }
}

bool InvertInformation(const MotionalMatrix& information, MotionalMatrix* inverse) {
  Eigen::MatrixXd result;
  if (!InvertInformation(Eigen::MatrixXd(information), &result)) return false;
  *inverse = result;
  return true;
}

MotionalMatrix LogToNaturalCovariance(const MotionalImpedance& p, const MotionalMatrix& c_log) {
  const MotionalVector v = ToNaturalVector(p);
  return v.asDiagonal() * c_log * v.asDiagonal();
}

}  // namespace eol::analysis
