// FitPod (analysis/qc/pod.h) against cases computed by hand.
//
// Two sizes only: a logistic (or probit) line through two points fits the observed hit
// shares exactly, so the maximum likelihood estimate is eta(x_k) = F^-1(h_k / n_k), and the
// inverse Fisher information gives var eta(x_k) = 1 / (n_k p_k (1 - p_k)) for the logit
// (F(1-F) / f^2 / n for the probit), independent at the two sizes. Everything else follows:
// b1 = (eta2 - eta1) / (x2 - x1), a90 = x where eta = F^-1(0.9), and the Wald a90/95 where
// eta(x) - z_0.95 sd(eta(x)) = F^-1(0.9) with eta(x) the linear interpolation of the two
// (a quadratic in x, solved below).
#include "analysis/qc/pod.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>

#include "analysis/qc/tolerance.h"

namespace eol::analysis {
namespace {

std::vector<HitMiss> TwoSizes(double x1, int n1, int h1, double x2, int n2, int h2) {
  std::vector<HitMiss> d;
  for (int i = 0; i < n1; ++i) d.push_back({x1, i < h1});
  for (int i = 0; i < n2; ++i) d.push_back({x2, i < h2});
  return d;
}

// Wald a90/95 of the two-size case: eta(u) = e1 + (e2 - e1) u, var(u) = v1 (1-u)^2 + v2 u^2,
// u = (x - x1) / (x2 - x1); solves e(u) - q = z sqrt(var(u)) for the root with e(u) > q.
double TwoSizeWald(double x1, double x2, double e1, double e2, double v1, double v2, double q,
                   double z) {
  const double A = e2 - e1, B = e1 - q, z2 = z * z;
  const double qa = A * A - z2 * (v1 + v2), qb = 2 * A * B + 2 * z2 * v1, qc = B * B - z2 * v1;
  const double disc = std::sqrt(qb * qb - 4 * qa * qc);
  for (double u : {(-qb + disc) / (2 * qa), (-qb - disc) / (2 * qa)})
    if (A * u + B > 0) return x1 + u * (x2 - x1);
  return NAN;
}

TEST(Pod, LogitTwoSizesByHand) {
  const std::vector<HitMiss> d = TwoSizes(0.4, 10, 2, 0.8, 10, 8);
  const PodSummary s = FitPod(d, PodOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  const double l4 = std::log(4.0);
  EXPECT_NEAR(s.b1, 5.0 * l4, 1e-7);
  EXPECT_NEAR(s.b0, -3.0 * l4, 1e-7);
  EXPECT_NEAR(s.a50, 0.6, 1e-9);
  EXPECT_NEAR(s.a90, (std::log(9.0) + 3.0 * l4) / (5.0 * l4), 1e-9);
  // Covariance: eta1 and eta2 independent, each 1 / (10 x 0.16) = 0.625.
  EXPECT_NEAR(s.cov11, 2 * 0.625 / (0.4 * 0.4), 1e-6);
  const double wald =
      TwoSizeWald(0.4, 0.8, -l4, l4, 0.625, 0.625, std::log(9.0), NormalQuantile(0.95));
  EXPECT_NEAR(s.a90_95_wald, wald, 1e-7);
  EXPECT_NEAR(s.PodLowerWald(s.a90_95_wald), 0.9, 1e-9);
  // Likelihood ratio: the profile deviance is z^2 = 2.706 at the bound, 0 at a90.
  ASSERT_TRUE(std::isfinite(s.a90_95_lr));
  EXPECT_GT(s.a90_95_lr, s.a90);
  EXPECT_NEAR(PodProfileDeviance(d, s, s.a90), 0.0, 1e-9);
  EXPECT_NEAR(PodProfileDeviance(d, s, s.a90_95_lr), std::pow(NormalQuantile(0.95), 2), 1e-6);
  // Log-likelihood at the estimate: each size at its own share.
  const double ll = 2 * (2 * std::log(0.2) + 8 * std::log(0.8));
  EXPECT_NEAR(s.log_likelihood, ll, 1e-9);
}

TEST(Pod, ProbitTwoSizesByHand) {
  PodOptions o;
  o.link = PodLink::kProbit;
  o.scale = PodScale::kLog;
  const std::vector<HitMiss> d = TwoSizes(0.5, 20, 5, 0.9, 20, 16);
  const PodSummary s = FitPod(d, o);
  ASSERT_TRUE(s.usable) << s.message;
  const double x1 = std::log(0.5), x2 = std::log(0.9);
  const double e1 = NormalQuantile(0.25), e2 = NormalQuantile(0.8);
  EXPECT_NEAR(s.b1, (e2 - e1) / (x2 - x1), 1e-6);
  const double x90 = x1 + (NormalQuantile(0.9) - e1) / (e2 - e1) * (x2 - x1);
  EXPECT_NEAR(s.a90, std::exp(x90), 1e-7);
  auto var = [](double e, double p, int n) {
    const double f = std::exp(-0.5 * e * e) / std::sqrt(2 * std::numbers::pi);
    return p * (1 - p) / (f * f * n);
  };
  const double wald = TwoSizeWald(x1, x2, e1, e2, var(e1, 0.25, 20), var(e2, 0.8, 20),
                                  NormalQuantile(0.9), NormalQuantile(0.95));
  EXPECT_NEAR(s.a90_95_wald, std::exp(wald), 1e-6);
}

TEST(Pod, RecoversAKnownCurve) {
  // 4000 units, a uniform on 0.2-0.99, true logit POD with a50 0.7 and a90 0.8.
  std::mt19937_64 gen(12);
  std::uniform_real_distribution<double> size(0.2, 0.99), u(0.0, 1.0);
  const double b1 = std::log(9.0) / 0.1, b0 = -0.7 * b1;
  std::vector<HitMiss> d;
  for (int i = 0; i < 4000; ++i) {
    const double a = size(gen);
    d.push_back({a, u(gen) < 1.0 / (1.0 + std::exp(-(b0 + b1 * a)))});
  }
  const PodSummary s = FitPod(d, PodOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_NEAR(s.a50, 0.7, 0.01);
  EXPECT_NEAR(s.a90, 0.8, 0.01);
  EXPECT_GT(s.a90_95_lr, s.a90);
  EXPECT_LT(s.a90_95_lr, s.a90 + 0.02);
  EXPECT_NEAR(s.a90_95_lr, s.a90_95_wald, 0.005);
  // A few misses beyond a90/95 are expected (POD 0.9+ there, not 1) and counted by hand.
  int beyond = 0;
  for (const HitMiss& h : d) beyond += !h.hit && h.size >= s.a90_95_lr ? 1 : 0;
  EXPECT_EQ(s.misses_beyond_a90_95, beyond);
  EXPECT_GT(beyond, 0);
}

TEST(Pod, SeparatedDataHaveNoEstimate) {
  const PodSummary s = FitPod(TwoSizes(0.3, 5, 0, 0.9, 5, 5), PodOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("do not overlap"), std::string::npos) << s.message;
  const PodSummary none = FitPod(TwoSizes(0.3, 5, 0, 0.9, 5, 0), PodOptions{});
  EXPECT_FALSE(none.usable);
  EXPECT_NE(none.message.find("no hits"), std::string::npos) << none.message;
  const PodSummary bad = FitPod({{0.0, true}, {0.5, false}}, PodOptions{});
  EXPECT_FALSE(bad.usable);
  EXPECT_NE(bad.message.find("must be finite and > 0"), std::string::npos) << bad.message;
}

TEST(Pod, UnboundedA9095IsSaid) {
  // Few units, POD hardly rising: a90 lies far out and the data do not bound it.
  const PodSummary s = FitPod(TwoSizes(0.4, 4, 1, 0.8, 4, 2), PodOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_FALSE(std::isfinite(s.a90_95_wald));
  EXPECT_FALSE(std::isfinite(s.a90_95_lr));
  EXPECT_NE(s.message.find("do not bound"), std::string::npos) << s.message;
  // Why: far out the profile flattens towards one POD for every size, whose deviance is
  // 2 (l_max - l_0) = 0.540 < z^2 = 2.706 (l_max: each size at its share; l_0: 3 of 8).
  const double l_max =
      4 * (0.25 * std::log(0.25) + 0.75 * std::log(0.75)) + 8 * 0.5 * std::log(0.5);
  const double l_0 = 3 * std::log(3.0 / 8) + 5 * std::log(5.0 / 8);
  EXPECT_NEAR(s.log_likelihood, l_max, 1e-9);
  const double far = PodProfileDeviance(TwoSizes(0.4, 4, 1, 0.8, 4, 2), s, 1e4);
  EXPECT_NEAR(far, 2 * (l_max - l_0), 1e-3);
  EXPECT_LT(far, 2 * (l_max - l_0));  // the profile rises towards it
}

}  // namespace
}  // namespace eol::analysis
