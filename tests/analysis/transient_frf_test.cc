// The transient-aware periodic estimator (analysis/signal/transient_frf.h) on recordings
// simulated FROM REST in the time domain (analysis/sim/time_domain.h, through
// SimulateRecordingFromRest): the start transient is in the record, both channels.
// The station's fast recipe: 200-800 Hz at 4 Hz spacing, 8 kHz, 2 periods (0.5 s), the
// simulated DAQ's noise (2 mV, 1 mA rms per sample).
#include "analysis/signal/transient_frf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "analysis/bench/fit_bench.h"
#include "analysis/impedance_analysis.h"
#include "analysis/signal/multisine.h"

namespace eol::analysis {
namespace {

const MotionalImpedance kTruth{0.5, 2.0e-3, 0.51, 390.0, 50.0};
constexpr double kSeriesOhm = 0.15;  // amplifier output + shunt: both channels see the transient

Excitation FastMultisine() {
  MultisineOptions o;
  o.line_spacing_hz = 4.0;
  return DesignMultisine(o);
}

TEST(TransientFrf, RemovesTheStartTransientOfANoiseFreeRecording) {
  const Excitation e = FastMultisine();
  const Recording rec = SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 0.0, 0.0, 1);
  // The line sigmas of the same record with the DAQ's noise: the scale errors are judged on.
  const FrfSummary noisy = EstimateTransientFrf(
      SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 2e-3, 1e-3, 1), e.lines, {});
  ASSERT_TRUE(noisy.usable) << noisy.message;
  const FrfSummary lpm = EstimateTransientFrf(rec, e.lines, TransientFrfOptions{});
  ASSERT_TRUE(lpm.usable) << lpm.message;
  EXPECT_EQ(lpm.frf.method, "transient-lpm");
  EXPECT_EQ(lpm.periods_used, 2u);
  ASSERT_EQ(lpm.frf.size(), e.lines.size());
  ASSERT_EQ(noisy.frf.size(), e.lines.size());
  // Averaging both periods, transient and all (the old estimator told not to drop any):
  PeriodicFrfOptions keep_all;
  keep_all.transient_periods = 0;
  keep_all.transient_threshold = 1e9;
  const FrfSummary avg = EstimatePeriodicFrf(rec, e.lines, keep_all);
  ASSERT_TRUE(avg.usable) << avg.message;
  double worst_lpm = 0.0, worst_avg = 0.0;
  for (std::size_t k = 0; k < e.lines.size(); ++k) {
    const auto z = kTruth.At(lpm.frf.freq_hz[k]);
    worst_lpm = std::max(worst_lpm, std::abs(lpm.frf.value[k] - z) / noisy.frf.sigma[k]);
    worst_avg = std::max(worst_avg, std::abs(avg.frf.value[k] - z) / noisy.frf.sigma[k]);
  }
  // The residue sits at the resonance (its transient is about as narrow as the window):
  // seen 0.68 sigma at 392 Hz; averaging without removal is off by 14 sigma.
  EXPECT_LT(worst_lpm, 1.0);
  EXPECT_GT(worst_avg, 5.0);
  // The station's estimator as configured (drop 1, keep >= 2) refuses a 2-period record.
  const FrfSummary drop = EstimatePeriodicFrf(rec, e.lines, PeriodicFrfOptions{});
  EXPECT_FALSE(drop.usable);
  EXPECT_NE(drop.message.find("only 2 whole periods recorded; need 3"), std::string::npos)
      << drop.message;
}

TEST(TransientFrf, RefusesBadData) {
  const Excitation e = FastMultisine();
  Recording rec = SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 2e-3, 1e-3, 3);
  {
    Recording bad = rec;
    bad.voltage_v[17] = std::numeric_limits<double>::quiet_NaN();
    const FrfSummary s = EstimateTransientFrf(bad, e.lines, {});
    EXPECT_FALSE(s.usable);
    EXPECT_EQ(s.message, "voltage sample 17 is not finite (NaN or inf)");
  }
  {
    Recording bad = rec;
    bad.current_full_scale_a = 0.05;  // far below the current's peak
    const FrfSummary s = EstimateTransientFrf(bad, e.lines, {});
    EXPECT_FALSE(s.usable);
    EXPECT_TRUE(s.clipped);
    EXPECT_EQ(s.message.rfind("current clipped at 0.05 A: ", 0), 0u) << s.message;
  }
  {
    Recording open = rec;  // relay open: the current channel reads its noise only
    std::mt19937_64 rng(5);
    std::normal_distribution<double> noise(0.0, 1e-3);
    for (double& v : open.current_a) v = noise(rng);
    const FrfSummary s = EstimateTransientFrf(open, e.lines, {});
    EXPECT_FALSE(s.usable);
    EXPECT_EQ(s.message.rfind("no signal: ", 0), 0u) << s.message;
  }
  {
    Recording one = rec;
    one.voltage_v.resize(e.period_samples);
    one.current_a.resize(e.period_samples);
    const FrfSummary s = EstimateTransientFrf(one, e.lines, {});
    EXPECT_FALSE(s.usable);
    EXPECT_NE(s.message.find("needs 2"), std::string::npos) << s.message;
  }
  TransientFrfOptions o;
  o.degree = 4;
  o.half_width = 2;
  const FrfSummary s = EstimateTransientFrf(rec, e.lines, o);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("half_width"), std::string::npos) << s.message;
}

// The reported sigma is E|dZ|^2 with its pooled variance on noise_dof complex degrees of
// freedom: over seeds, |Z_hat - Z|^2 / sigma_hat^2 averages nu / (nu - 2), nu = 2 noise_dof
// (the mean of 1 / chi2), across the band.
TEST(TransientFrf, SigmaAndItsDegreesOfFreedomMatchTheScatterOfZ) {
  const Excitation e = FastMultisine();
  double sum = 0.0, dof = 0.0;
  std::size_t count = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Recording rec = SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 2e-3, 1e-3, seed);
    const FrfSummary s = EstimateTransientFrf(rec, e.lines, {});
    ASSERT_TRUE(s.usable) << s.message;
    dof = s.noise_dof;
    for (std::size_t k = 0; k < s.frf.size(); ++k) {
      sum += std::norm(s.frf.value[k] - kTruth.At(s.frf.freq_hz[k])) / std::pow(s.frf.sigma[k], 2);
      ++count;
    }
  }
  const double nu = 2.0 * dof;
  EXPECT_GT(dof, 12.0);  // seen 17.6
  // 6000 terms, correlated over the pooling: mean within 4 % of the expectation.
  EXPECT_NEAR(sum / static_cast<double>(count), nu / (nu - 2.0), 0.04) << "noise dof " << dof;
}

FitBenchOptions FastBench(FrfMethod method) {
  FitBenchOptions o;
  o.truth = kTruth;
  o.excitation.line_spacing_hz = 4.0;
  o.simulation = BenchSimulation::kTimeDomain;
  o.series_ohm = kSeriesOhm;
  o.analysis.frf_method = method;
  o.analysis.fit.f0_min_hz = 250.0;
  o.analysis.fit.f0_max_hz = 700.0;
  o.transient_periods = 0;
  o.periods = 2;
  o.runs = 300;
  o.check_runs = 0;
  o.seed = 11;
  return o;
}

// f0 through the new estimator and the station's fit on 300 records of 0.5 s from rest:
// unbiased, at the Cramer-Rao bound of that record, honest sigma.
TEST(TransientFrf, ResonanceFitReachesTheBoundOfTheShortRecord) {
  const FitBenchResult r = RunFitBench(FastBench(FrfMethod::kTransientLpm));
  ASSERT_EQ(r.usable_runs, r.runs) << r.first_failure;
  // (a) bias: the transient's residue at the resonance pulls f0 up by about 0.25 std (seen
  // +0.0064 Hz, 0.245 std over 1000 runs); the std of the mean over 300 runs is 0.06 std.
  EXPECT_LT(std::abs(r.bias_over_std), 0.4) << "bias " << r.ml_bias_hz << " Hz";
  // (b) against the bound of the channels' true noise over both periods (the station's target,
  // the transient removal's price included; seen 1.03 over 1000 runs), and against the bound
  // of the estimator's own sigma (seen 0.9: the leverage term is conservative for f0). The
  // std of a 300-run std is 4 %.
  EXPECT_LT(r.std_over_crb_true_noise, 1.1)
      << "std " << r.f0_std_hz << " true-noise crb " << r.crb_true_noise_f0_hz;
  EXPECT_LT(r.std_over_crb, 1.1) << "std " << r.f0_std_hz << " crb " << r.crb_f0_hz;
  // (c) coverage of +-2 sigma: 95 %, binomial std 1.3 % at 300 runs (seen 96 %).
  EXPECT_GT(r.coverage_2sigma, 0.91);
  EXPECT_LT(r.coverage_2sigma, 0.99);
  EXPECT_GT(r.noise_dof, 10.0);
}

// (d) The same records through today's estimator: with the first period dropped one period is
// left and there is no sigma (every run refused); keeping it, the transient biases f0.
TEST(TransientFrf, TheDiscardingEstimatorCannotUseTheSameRecords) {
  FitBenchOptions o = FastBench(FrfMethod::kDiscardTransient);
  o.runs = 20;
  o.transient_periods = 1;
  o.periods = 1;
  o.analysis.frf.min_periods = 2;
  // IsValid rejects it up front: 1 period cannot give a sigma.
  std::string why;
  EXPECT_FALSE(o.IsValid(&why));
  o.periods = 2;
  o.transient_periods = 0;
  o.analysis.frf.transient_periods = 0;
  o.analysis.frf.transient_threshold = 1e9;  // keep the transient period in the average
  o.runs = 100;
  const FitBenchResult keep = RunFitBench(o);
  ASSERT_GE(keep.usable_runs, 2) << keep.first_failure;
  // Biased by several of its own standard deviations, or its sigma does not cover.
  EXPECT_TRUE(std::abs(keep.bias_over_std) > 3.0 || keep.coverage_2sigma < 0.8)
      << "bias " << keep.ml_bias_hz << " Hz (" << keep.bias_over_std << " std), coverage "
      << keep.coverage_2sigma;
}

}  // namespace
}  // namespace eol::analysis
