// Known-answer tests of FitMotionalResonance (analysis/fit/resonance_fit.h).
// The reference motor is the paper's measured case (analysis/README.md 2): R = 0.5 ohm, L = 2 mH,
// Rp = 0.5 ohm, f0 = 390 Hz, Q = 50, lines 200..800 Hz at 1 Hz. Noise is circular complex
// Gaussian with E|dZ|^2 = sigma^2; sigma = 0.02 ohm puts the peak at SNR_pk = 625 and the f0
// bound near 0.045 Hz, the regime of analysis/README.md 4.
#include "analysis/fit/resonance_fit.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>

#include "analysis/fit/cramer_rao.h"
#include "analysis/fit/motional_jacobian.h"

namespace eol::analysis {
namespace {

// Message matching with gtest alone (the test links gtest, not gmock).
#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

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

// The model on `freq` plus circular complex Gaussian noise of std sigma; sigma recorded.
Frf Noisy(const MotionalImpedance& m, const std::vector<double>& freq, double sigma,
          std::mt19937_64* rng) {
  Frf z = m.Evaluate(freq);
  std::normal_distribution<double> n(0.0, sigma / std::sqrt(2.0));
  for (auto& v : z.value) v += std::complex<double>(n(*rng), n(*rng));
  z.sigma.assign(freq.size(), sigma);
  z.method = "synthetic";
  return z;
}

double Value(const FitSummary& s, const char* name) {
  const FittedParameter* p = s.Find(name);
  return p ? p->value : std::numeric_limits<double>::quiet_NaN();
}
double Sigma(const FitSummary& s, const char* name) {
  const FittedParameter* p = s.Find(name);
  return p ? p->sigma : std::numeric_limits<double>::quiet_NaN();
}

// The analytic Jacobian against central differences of the model, every parameter, at lines
// below, at and above f0 (the derivative code the fit and the bound share).
TEST(FitMotionalJacobianTest, MatchesCentralDifferences) {
  const MotionalImpedance m = Reference();
  const MotionalVector theta = ToLogParams(m);
  for (double f : {200.0, 385.0, 390.0, 391.3, 800.0}) {
    const MotionalPoint pt = EvaluateMotional(m, f);
    EXPECT_NEAR(std::abs(pt.z - m.At(f)), 0.0, 1e-12 * std::abs(m.At(f)));
    for (int i = 0; i < kMotionalParamCount; ++i) {
      const double h = 1e-6;
      MotionalVector tp = theta, tm = theta;
      tp[i] += h;
      tm[i] -= h;
      const std::complex<double> numeric =
          (FromLogParams(tp).At(f) - FromLogParams(tm).At(f)) / (2.0 * h);
      const std::complex<double> analytic = pt.dz_dtheta[static_cast<std::size_t>(i)];
      EXPECT_NEAR(std::abs(analytic - numeric), 0.0, 1e-6 * (std::abs(analytic) + 1e-3))
          << "f = " << f << " Hz, parameter " << kMotionalParamNames[static_cast<std::size_t>(i)];
    }
  }
}

// Noise-free data: every parameter back to 1e-6 relative, chi2 ~ 0.
TEST(ResonanceFitTest, NoiseFreeRecoversParameters) {
  const MotionalImpedance truth = Reference();
  Frf z = truth.Evaluate(Lines(200.0, 800.0, 1.0));
  z.sigma.assign(z.size(), 0.02);
  const FitSummary s = FitMotionalResonance(z, ResonanceFitOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.termination, Termination::kConverged);
  ASSERT_EQ(s.params.size(), 5u);
  EXPECT_EQ(s.params[0].name, "R_ohm");
  EXPECT_EQ(s.params[1].name, "L_h");
  EXPECT_EQ(s.params[2].name, "Rp_ohm");
  EXPECT_EQ(s.params[3].name, "f0_hz");
  EXPECT_EQ(s.params[4].name, "Q");
  EXPECT_EQ(s.params[3].unit, "Hz");
  EXPECT_NEAR(Value(s, "R_ohm"), 0.5, 0.5e-6);
  EXPECT_NEAR(Value(s, "L_h"), 2e-3, 2e-9);
  EXPECT_NEAR(Value(s, "Rp_ohm"), 0.5, 0.5e-6);
  EXPECT_NEAR(Value(s, "f0_hz"), 390.0, 390e-6);
  EXPECT_NEAR(Value(s, "Q"), 50.0, 50e-6);
  EXPECT_LT(s.chi2, 1e-6);
  EXPECT_EQ(s.dof, 2 * 601 - 5);
  EXPECT_FALSE(s.sigma_estimated);
  const MotionalImpedance back = s.Model();
  EXPECT_NEAR(back.f0_hz, 390.0, 390e-6);
  EXPECT_NEAR(back.q, 50.0, 50e-6);
  EXPECT_EQ(s.Find("no_such_parameter"), nullptr);
}

// A sharper, weaker and differently placed mode, found from the data band alone.
TEST(ResonanceFitTest, NoiseFreeHighQOffCentre) {
  MotionalImpedance truth = Reference();
  truth.f0_hz = 612.3;
  truth.q = 400.0;
  truth.rp_ohm = 0.08;
  Frf z = truth.Evaluate(Lines(200.0, 800.0, 0.5));
  z.sigma.assign(z.size(), 1e-3);
  const FitSummary s = FitMotionalResonance(z, ResonanceFitOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_NEAR(Value(s, "f0_hz"), truth.f0_hz, truth.f0_hz * 1e-6);
  EXPECT_NEAR(Value(s, "Q"), truth.q, truth.q * 1e-6);
  EXPECT_NEAR(Value(s, "Rp_ohm"), truth.rp_ohm, truth.rp_ohm * 1e-6);
}

// One noisy realisation (seed 1): f0 within 3 reported sigma, the others within 4, the
// reported f0 sigma close to the Cramer-Rao bound, chi2/dof consistent with 1.
TEST(ResonanceFitTest, NoisyDataWithinReportedSigma) {
  const MotionalImpedance truth = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  const double sigma = 0.02;
  std::mt19937_64 rng(1);
  const FitSummary s = FitMotionalResonance(Noisy(truth, f, sigma, &rng), ResonanceFitOptions{});
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_CONTAINS(s.message, "converged");
  EXPECT_NEAR(Value(s, "f0_hz"), 390.0, 3.0 * Sigma(s, "f0_hz"));
  EXPECT_NEAR(Value(s, "R_ohm"), 0.5, 4.0 * Sigma(s, "R_ohm"));
  EXPECT_NEAR(Value(s, "L_h"), 2e-3, 4.0 * Sigma(s, "L_h"));
  EXPECT_NEAR(Value(s, "Rp_ohm"), 0.5, 4.0 * Sigma(s, "Rp_ohm"));
  EXPECT_NEAR(Value(s, "Q"), 50.0, 4.0 * Sigma(s, "Q"));
  const CramerRaoBound crb = ComputeCramerRaoBound(truth, f, sigma);
  ASSERT_TRUE(crb.valid) << crb.message;
  EXPECT_NEAR(Sigma(s, "f0_hz") / crb.Std(kParamF0), 1.0, 0.05);
  // chi2 ~ chi-square(1197): std of chi2/dof is sqrt(2/1197) = 0.041.
  EXPECT_NEAR(s.chi2_per_dof, 1.0, 4.0 * std::sqrt(2.0 / s.dof));
  ASSERT_EQ(s.covariance.rows(), 5);
  ASSERT_EQ(s.covariance.cols(), 5);
  EXPECT_NEAR(std::sqrt(s.covariance(3, 3)), Sigma(s, "f0_hz"), 1e-12);
}

// 200 realisations (seed 2024): the estimator reaches the Cramer-Rao bound (sample std of f0
// over the bound in [0.85, 1.2]; the sample std has about 5 % relative spread) and chi2/dof
// averages to 1 within 5 %.
TEST(ResonanceFitTest, MonteCarloReachesCramerRaoBound) {
  const auto t0 = std::chrono::steady_clock::now();
  const MotionalImpedance truth = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  const double sigma = 0.02;
  const int runs = 200;
  std::mt19937_64 rng(2024);
  double sum_f0 = 0.0, sum_f0_sq = 0.0, sum_q = 0.0, sum_q_sq = 0.0, sum_chi2 = 0.0;
  double sum_reported = 0.0;
  int usable = 0;
  for (int i = 0; i < runs; ++i) {
    const FitSummary s = FitMotionalResonance(Noisy(truth, f, sigma, &rng), ResonanceFitOptions{});
    if (!s.usable) {
      ADD_FAILURE() << "run " << i << ": " << s.message;
      continue;
    }
    ++usable;
    const double df0 = Value(s, "f0_hz") - truth.f0_hz;
    const double dq = Value(s, "Q") - truth.q;
    sum_f0 += df0;
    sum_f0_sq += df0 * df0;
    sum_q += dq;
    sum_q_sq += dq * dq;
    sum_chi2 += s.chi2_per_dof;
    sum_reported += Sigma(s, "f0_hz");
  }
  ASSERT_EQ(usable, runs);
  const double n = runs;
  const double mean_f0 = sum_f0 / n;
  const double std_f0 = std::sqrt((sum_f0_sq - n * mean_f0 * mean_f0) / (n - 1));
  const double mean_q = sum_q / n;
  const double std_q = std::sqrt((sum_q_sq - n * mean_q * mean_q) / (n - 1));
  const CramerRaoBound crb = ComputeCramerRaoBound(truth, f, sigma);
  ASSERT_TRUE(crb.valid) << crb.message;
  const double ratio = std_f0 / crb.Std(kParamF0);
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf(
      "Monte Carlo %d runs: std(f0) = %.5f Hz, CRB = %.5f Hz, ratio %.3f; mean f0 error %.5f Hz;"
      " std(Q)/CRB = %.3f; mean reported sigma(f0) = %.5f Hz; mean chi2/dof = %.4f; %.2f s\n",
      runs, std_f0, crb.Std(kParamF0), ratio, mean_f0, std_q / crb.Std(kParamQ), sum_reported / n,
      sum_chi2 / n, seconds);
  EXPECT_GE(ratio, 0.85);
  EXPECT_LE(ratio, 1.2);
  EXPECT_NEAR(std_q / crb.Std(kParamQ), 1.0, 0.2);
  // Unbiased within 4 standard errors of the mean.
  EXPECT_NEAR(mean_f0, 0.0, 4.0 * crb.Std(kParamF0) / std::sqrt(n));
  EXPECT_NEAR(sum_chi2 / n, 1.0, 0.05);
  EXPECT_NEAR(sum_reported / n / crb.Std(kParamF0), 1.0, 0.05);
}

// Without sigma: unit weights, noise estimated from the residual, covariance scaled by it.
TEST(ResonanceFitTest, NoSigmaEstimatesNoiseFromResidual) {
  const MotionalImpedance truth = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  const double sigma = 0.02;
  std::mt19937_64 rng(7);
  Frf with_sigma = Noisy(truth, f, sigma, &rng);
  Frf without = with_sigma;
  without.sigma.clear();
  const FitSummary known = FitMotionalResonance(with_sigma, ResonanceFitOptions{});
  const FitSummary s = FitMotionalResonance(without, ResonanceFitOptions{});
  ASSERT_TRUE(known.usable) << known.message;
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_TRUE(s.sigma_estimated);
  EXPECT_FALSE(known.sigma_estimated);
  EXPECT_CONTAINS(s.message, "no sigma");
  EXPECT_CONTAINS(s.message, "estimated from the residual");
  // The estimated sigma has relative spread 1/sqrt(2 dof) ~ 2 %.
  EXPECT_NEAR(s.estimated_sigma, sigma, 0.1 * sigma);
  EXPECT_NEAR(s.chi2_per_dof, 1.0, 1e-9);
  // Uniform sigma: the weighted and unweighted optima coincide; the covariances differ only by
  // the noise scale.
  for (const char* name : {"R_ohm", "L_h", "Rp_ohm", "f0_hz", "Q"}) {
    EXPECT_NEAR(Value(s, name), Value(known, name), 1e-6 * std::abs(Value(known, name))) << name;
    EXPECT_NEAR(Sigma(s, name) / Sigma(known, name), s.estimated_sigma / sigma, 1e-4) << name;
  }
  EXPECT_NEAR(Value(s, "f0_hz"), 390.0, 3.0 * Sigma(s, "f0_hz"));
}

TEST(ResonanceFitTest, InvalidInputsAreReportedNotThrown) {
  const MotionalImpedance truth = Reference();
  const std::vector<double> f = Lines(200.0, 800.0, 1.0);
  Frf good = truth.Evaluate(f);
  good.sigma.assign(f.size(), 0.02);

  Frf nan_value = good;
  nan_value.value[17] = {std::nan(""), 0.0};
  FitSummary s = FitMotionalResonance(nan_value, ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "line 17");
  EXPECT_CONTAINS(s.message, "not finite");

  s = FitMotionalResonance(Frf{}, ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "no lines");

  Frf mobility = good;
  mobility.quantity = Quantity::kMobility;
  s = FitMotionalResonance(mobility, ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "quantity is mobility_rad_per_s_per_a");

  Frf few = truth.Evaluate(Lines(385.0, 393.0, 1.0));
  s = FitMotionalResonance(few, ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "9 lines, the fit needs at least 10");

  Frf bad_sigma = good;
  bad_sigma.sigma[3] = -1.0;
  s = FitMotionalResonance(bad_sigma, ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "sigma must be finite and positive");

  ResonanceFitOptions bad_options;
  bad_options.q_min = 0.0;
  s = FitMotionalResonance(good, bad_options);
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "q_min");

  ResonanceFitOptions outside;
  outside.f0_min_hz = 1000.0;
  outside.f0_max_hz = 2000.0;
  s = FitMotionalResonance(good, outside);
  EXPECT_FALSE(s.usable);
  EXPECT_EQ(s.termination, Termination::kInvalidInput);
  EXPECT_CONTAINS(s.message, "does not overlap the data band");
}

// T(phi) ~ 0 (no coupling): R + j w L and noise only. No resonance, and the fit says so.
TEST(ResonanceFitTest, NoCouplingGivesNoResonance) {
  MotionalImpedance m = Reference();
  m.rp_ohm = 1e-9;
  std::mt19937_64 rng(3);
  const FitSummary s =
      FitMotionalResonance(Noisy(m, Lines(200.0, 800.0, 1.0), 0.02, &rng), ResonanceFitOptions{});
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "no resonance found between 200 and 800 Hz");
}

// The mode lies outside the requested search range: the fit runs to the range's edge.
TEST(ResonanceFitTest, ResonanceOutsideSearchRangeIsNotUsable) {
  std::mt19937_64 rng(4);
  ResonanceFitOptions options;
  options.f0_min_hz = 450.0;
  options.f0_max_hz = 750.0;
  const FitSummary s =
      FitMotionalResonance(Noisy(Reference(), Lines(200.0, 800.0, 1.0), 0.02, &rng), options);
  EXPECT_FALSE(s.usable);
  EXPECT_CONTAINS(s.message, "no resonance found between 450 and 750 Hz");
}

TEST(ResonanceFitOptionsTest, ValidationNamesTheField) {
  std::string why;
  EXPECT_TRUE(ResonanceFitOptions{}.IsValid(&why));
  ResonanceFitOptions o;
  o.f0_min_hz = 500.0;
  o.f0_max_hz = 400.0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_CONTAINS(why, "f0_min_hz");
  o = ResonanceFitOptions{};
  o.grid_f0 = 1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_CONTAINS(why, "grid_f0");
  o = ResonanceFitOptions{};
  o.max_iterations = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_CONTAINS(why, "max_iterations");
}

}  // namespace
}  // namespace eol::analysis
