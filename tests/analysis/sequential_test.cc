// The pieces of the sequential decision (issue 16): which measurements are undecided
// (analysis/qc/measurement.h) and how two looks become one estimate (analysis/frf.h).
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/frf.h"
#include "analysis/qc/measurement.h"

namespace eol::analysis {
namespace {

Measurement M(const std::string& name, double value, double sigma, std::optional<double> lo,
              std::optional<double> hi, double marginal = 0.0) {
  Measurement m;
  m.name = name;
  m.value = value;
  m.sigma = sigma;
  m.limit.lo = lo;
  m.limit.hi = hi;
  m.limit.marginal = marginal;
  return m;
}

TEST(UndecidedMeasurements, WithinZSigmaOrTheMarginalBandOnEitherSide) {
  const std::vector<Measurement> ms = {
      M("far", 390.0, 0.01, 370.0, 420.0),                // decided
      M("near_pass", 370.02, 0.01, 370.0, 420.0),         // 2 sigma inside the lower bound
      M("near_fail", 369.98, 0.01, 370.0, 420.0),         // 2 sigma outside: could be a pass
      M("chi2_band", 1.18, std::nan(""), {}, 1.2, 0.05),  // no sigma: the marginal band
      M("chi2_clear", 2.0, std::nan(""), {}, 1.2, 0.05),  // a clear FAIL
      M("broken", std::nan(""), 0.01, 370.0, 420.0),      // ERROR: more looks do not help
      M("open", 5.0, 1.0, {}, {}),                        // no bound at all
  };
  const std::vector<std::string> u = UndecidedMeasurements(ms, 3.0);
  EXPECT_EQ(u, (std::vector<std::string>{"near_pass", "near_fail", "chi2_band"}));
  // A smaller z decides more.
  EXPECT_EQ(UndecidedMeasurements(ms, 1.0), (std::vector<std::string>{"chi2_band"}));
}

Frf Look(double value, double sigma, std::size_t n) {
  Frf f;
  for (std::size_t k = 0; k < n; ++k) {
    f.freq_hz.push_back(100.0 + static_cast<double>(k));
    f.value.emplace_back(value, -value);
    f.sigma.push_back(sigma);
  }
  f.method = "look";
  return f;
}

TEST(CombineIndependent, InverseVarianceWeights) {
  const Frf c = CombineIndependent(Look(1.0, 0.1, 3), Look(2.0, 0.2, 3));
  // weights 100 and 25: (100 * 1 + 25 * 2) / 125 = 1.2; sigma 1 / sqrt(125).
  EXPECT_NEAR(c.value[1].real(), 1.2, 1e-12);
  EXPECT_NEAR(c.value[1].imag(), -1.2, 1e-12);
  EXPECT_NEAR(c.sigma[2], 1.0 / std::sqrt(125.0), 1e-12);
  EXPECT_EQ(c.method, "look+look");
}

TEST(CombineIndependent, ReachesTheSigmaItReports) {
  // Two looks with noise of their stated sigma: the combination scatters as its own sigma.
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  double sum2 = 0;
  const int runs = 4000;
  for (int i = 0; i < runs; ++i) {
    Frf a = Look(0.0, 0.3, 1), b = Look(0.0, 0.1, 1);
    a.value[0] = {0.3 / std::sqrt(2.0) * n(rng), 0.3 / std::sqrt(2.0) * n(rng)};
    b.value[0] = {0.1 / std::sqrt(2.0) * n(rng), 0.1 / std::sqrt(2.0) * n(rng)};
    const Frf c = CombineIndependent(a, b);
    sum2 += std::norm(c.value[0]) / (c.sigma[0] * c.sigma[0]);
  }
  EXPECT_NEAR(sum2 / runs, 1.0, 0.06);  // E|dZ|^2 = sigma^2
}

TEST(CombineIndependent, RefusesWhatCannotBeWeighed) {
  Frf a = Look(1.0, 0.1, 3), b = Look(1.0, 0.1, 4);
  EXPECT_THROW(CombineIndependent(a, b), std::invalid_argument);
  b = Look(1.0, 0.1, 3);
  b.sigma.clear();
  try {
    CombineIndependent(a, b);
    FAIL() << "combined without sigma";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("sigma"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eol::analysis
