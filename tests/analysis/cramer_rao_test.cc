// Tests of the Cramer-Rao bound (analysis/fit/cramer_rao.h): the Fisher matrix against an
// independent finite-difference evaluation of the model, the analysis/README.md 4 closed forms, and
// the bound's scaling laws.
#include "analysis/fit/cramer_rao.h"

#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <numbers>

namespace eol::analysis {
namespace {

MotionalImpedance Reference() {
  MotionalImpedance m;
  m.r_ohm = 0.5;
  m.l_h = 2e-3;
  m.rp_ohm = 0.5;
  m.f0_hz = 390.0;
  m.q = 50.0;
  return m;
}

std::vector<double> Lines(double lo_hz, double hi_hz, double df_hz) {
  std::vector<double> f;
  for (double x = lo_hz; x <= hi_hz + 1e-9; x += df_hz) f.push_back(x);
  return f;
}

// F = sum_k (2 / sigma_k^2) Re(J_k^H J_k) with J_k from central differences of
// MotionalImpedance::At in ln p: independent of the analytic Jacobian.
MotionalMatrix FisherByFiniteDifferences(const MotionalImpedance& m, const std::vector<double>& f,
                                         double sigma) {
  const MotionalVector theta = ToLogParams(m);
  MotionalMatrix fisher = MotionalMatrix::Zero();
  const double h = 1e-6;
  for (double fk : f) {
    std::complex<double> d[kMotionalParamCount];
    for (int i = 0; i < kMotionalParamCount; ++i) {
      MotionalVector tp = theta, tm = theta;
      tp[i] += h;
      tm[i] -= h;
      d[i] = (FromLogParams(tp).At(fk) - FromLogParams(tm).At(fk)) / (2.0 * h);
    }
    for (int i = 0; i < kMotionalParamCount; ++i)
      for (int j = 0; j < kMotionalParamCount; ++j)
        fisher(i, j) += 2.0 / (sigma * sigma) * (std::conj(d[i]) * d[j]).real();
  }
  return fisher;
}

TEST(CramerRaoTest, FisherMatchesFiniteDifferences) {
  const MotionalImpedance m = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  const CramerRaoBound b = ComputeCramerRaoBound(m, f, 0.02);
  ASSERT_TRUE(b.valid) << b.message;
  const MotionalMatrix numeric = FisherByFiniteDifferences(m, f, 0.02);
  for (int i = 0; i < kMotionalParamCount; ++i)
    for (int j = 0; j < kMotionalParamCount; ++j)
      EXPECT_NEAR(b.fisher(i, j), numeric(i, j), 1e-6 * std::sqrt(numeric(i, i) * numeric(j, j)))
          << "(" << i << ", " << j << ")";
  // Natural-unit covariance: diag(p) F^-1 diag(p), std = sqrt of its diagonal.
  const MotionalMatrix c_log = b.fisher.inverse();
  EXPECT_NEAR(b.Std(kParamF0), 390.0 * std::sqrt(c_log(kParamF0, kParamF0)),
              1e-9 * b.Std(kParamF0));
  EXPECT_NEAR(b.covariance(kParamL, kParamF0), 2e-3 * 390.0 * c_log(kParamL, kParamF0),
              1e-9 * std::abs(b.covariance(kParamL, kParamF0)) + 1e-30);
}

// Known value of the closed form: B3dB = 7.8 Hz, N3 = 7.8, SNR_pk = 625:
// std(f0) = 7.8 / sqrt(2 pi 7.8 625) = 0.044568 Hz; std(Q)/Q = 2 / sqrt(pi 7.8 625) = 0.016161.
TEST(CramerRaoTest, ClosedFormKnownValues) {
  EXPECT_NEAR(CramerRaoF0ClosedFormHz(390.0, 50.0, 0.5, 1.0, 0.02), 0.044568, 1e-6);
  EXPECT_NEAR(CramerRaoQRelativeClosedForm(390.0, 50.0, 0.5, 1.0, 0.02), 0.016161, 1e-6);
}

// Lightly damped modes well inside the band: the full bound (all five parameters free, finite
// band) agrees with the closed forms of analysis/README.md 4 within 15 %.
TEST(CramerRaoTest, AgreesWithClosedFormWhenLightlyDamped) {
  struct Case {
    double f0_hz, q, rp_ohm, df_hz, sigma;
  };
  for (const Case& c : {Case{390.0, 50.0, 0.5, 1.0, 0.02}, Case{390.0, 200.0, 0.5, 0.25, 0.02},
                        Case{520.0, 100.0, 0.2, 0.5, 0.01}}) {
    MotionalImpedance m = Reference();
    m.f0_hz = c.f0_hz;
    m.q = c.q;
    m.rp_ohm = c.rp_ohm;
    const CramerRaoBound b = ComputeCramerRaoBound(m, Lines(200.0, 800.0, c.df_hz), c.sigma);
    ASSERT_TRUE(b.valid) << b.message;
    const double f0_closed = CramerRaoF0ClosedFormHz(c.f0_hz, c.q, c.rp_ohm, c.df_hz, c.sigma);
    const double q_closed = CramerRaoQRelativeClosedForm(c.f0_hz, c.q, c.rp_ohm, c.df_hz, c.sigma);
    std::printf(
        "f0 = %g Hz, Q = %g: std(f0) bound %.5f Hz, closed form %.5f Hz (ratio %.3f); "
        "std(Q)/Q bound %.5f, closed form %.5f (ratio %.3f)\n",
        c.f0_hz, c.q, b.Std(kParamF0), f0_closed, b.Std(kParamF0) / f0_closed, b.Std(kParamQ) / c.q,
        q_closed, b.Std(kParamQ) / c.q / q_closed);
    EXPECT_NEAR(b.Std(kParamF0) / f0_closed, 1.0, 0.15) << "Q = " << c.q;
    EXPECT_NEAR(b.Std(kParamQ) / c.q / q_closed, 1.0, 0.15) << "Q = " << c.q;
  }
}

// The bound scales as sigma, and per-line sigma equals the uniform overload.
TEST(CramerRaoTest, ScalesWithSigma) {
  const MotionalImpedance m = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  const CramerRaoBound a = ComputeCramerRaoBound(m, f, 0.02);
  const CramerRaoBound b = ComputeCramerRaoBound(m, f, std::vector<double>(f.size(), 0.04));
  ASSERT_TRUE(a.valid && b.valid);
  for (int i = 0; i < kMotionalParamCount; ++i)
    EXPECT_NEAR(b.std_dev[static_cast<std::size_t>(i)] / a.std_dev[static_cast<std::size_t>(i)],
                2.0, 1e-9);
}

// Noise only at the peak: the lines far from f0 carry little information on f0 and Q.
TEST(CramerRaoTest, PerLineSigmaWeightsLines) {
  const MotionalImpedance m = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  std::vector<double> sigma(f.size(), 0.02);
  const CramerRaoBound uniform = ComputeCramerRaoBound(m, f, sigma);
  for (std::size_t k = 0; k < f.size(); ++k)
    if (std::abs(f[k] - 390.0) < 10.0) sigma[k] = 0.2;
  const CramerRaoBound noisy_peak = ComputeCramerRaoBound(m, f, sigma);
  ASSERT_TRUE(uniform.valid && noisy_peak.valid);
  EXPECT_GT(noisy_peak.Std(kParamF0), 3.0 * uniform.Std(kParamF0));
  EXPECT_LT(noisy_peak.Std(kParamL) / uniform.Std(kParamL), 1.2);
}

TEST(CramerRaoTest, InvalidInputs) {
  const MotionalImpedance m = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  CramerRaoBound b = ComputeCramerRaoBound(m, f, std::vector<double>(3, 0.02));
  EXPECT_FALSE(b.valid);
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, "one sigma per line", b.message);
  b = ComputeCramerRaoBound(m, f, 0.0);
  EXPECT_FALSE(b.valid);
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, "line 0", b.message);
  MotionalImpedance bad = m;
  bad.q = -1.0;
  b = ComputeCramerRaoBound(bad, f, 0.02);
  EXPECT_FALSE(b.valid);
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, "parameter Q", b.message);
  // Two lines cannot determine five parameters.
  b = ComputeCramerRaoBound(m, {389.0, 391.0}, 0.02);
  EXPECT_FALSE(b.valid);
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, "singular", b.message);
}

}  // namespace
}  // namespace eol::analysis
