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

// Largest |Z_hat - Z| / sigma_true-free error relative to |Z| over the lines.
double MaxRelativeError(const Frf& z, const MotionalImpedance& truth) {
  double worst = 0.0;
  for (std::size_t k = 0; k < z.size(); ++k) {
    const auto t = truth.At(z.freq_hz[k]);
    worst = std::max(worst, std::abs(z.value[k] - t) / std::abs(t));
  }
  return worst;
}

TEST(TransientFrf, RemovesTheStartTransientOfANoiseFreeRecording) {
  const Excitation e = FastMultisine();
  const Recording rec = SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 0.0, 0.0, 1);
  const FrfSummary lpm = EstimateTransientFrf(rec, e.lines, TransientFrfOptions{});
  ASSERT_TRUE(lpm.usable) << lpm.message;
  EXPECT_EQ(lpm.frf.method, "transient-lpm");
  EXPECT_EQ(lpm.periods_used, 2u);
  EXPECT_EQ(lpm.frf.size(), e.lines.size());
  const double err_lpm = MaxRelativeError(lpm.frf, kTruth);
  // Averaging both periods, transient and all (the old estimator told not to drop any):
  PeriodicFrfOptions keep_all;
  keep_all.transient_periods = 0;
  keep_all.transient_threshold = 1e9;
  const FrfSummary avg = EstimatePeriodicFrf(rec, e.lines, keep_all);
  ASSERT_TRUE(avg.usable) << avg.message;
  const double err_avg = MaxRelativeError(avg.frf, kTruth);
  EXPECT_LT(err_lpm, 2e-3);
  EXPECT_GT(err_avg, 20.0 * err_lpm) << "lpm " << err_lpm << " average " << err_avg;
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
    EXPECT_EQ(s.message.rfind("clipping: 0 voltage and ", 0), 0u) << s.message;
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

// The reported sigma is E|dZ|^2: over seeds, the normalised errors |Z_hat - Z|^2 / sigma^2
// average 1 across the band (transient removal's leverage and the pooled noise included).
TEST(TransientFrf, SigmaMatchesTheScatterOfZ) {
  const Excitation e = FastMultisine();
  double sum = 0.0;
  std::size_t count = 0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const Recording rec = SimulateRecordingFromRest(kTruth, e, 2, kSeriesOhm, 2e-3, 1e-3, seed);
    const FrfSummary s = EstimateTransientFrf(rec, e.lines, {});
    ASSERT_TRUE(s.usable) << s.message;
    for (std::size_t k = 0; k < s.frf.size(); ++k) {
      sum += std::norm(s.frf.value[k] - kTruth.At(s.frf.freq_hz[k])) / std::pow(s.frf.sigma[k], 2);
      ++count;
    }
  }
  // About 6000 terms, each ~ exponential(1) scaled by the sigma's own scatter: mean within 5 %.
  EXPECT_NEAR(sum / static_cast<double>(count), 1.0, 0.05);
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
  // (a) bias: the std of the mean is std / sqrt(300) = 0.058 std; allow 4 of those.
  EXPECT_LT(std::abs(r.bias_over_std), 0.23) << "bias " << r.ml_bias_hz << " Hz";
  // (b) against the bound with the estimator's own sigma and against the bound of the
  // channels' true noise over both periods (the transient removal's price included).
  // The std of a 300-run std is 4 %: 1.1 is 2.5 of those above 1.
  EXPECT_LT(r.std_over_crb, 1.1) << "std " << r.f0_std_hz << " crb " << r.crb_f0_hz;
  EXPECT_LT(r.std_over_crb_true_noise, 1.1 * std::sqrt(1.4))
      << "std " << r.f0_std_hz << " true-noise crb " << r.crb_true_noise_f0_hz;
  // (c) coverage of +-2 sigma: 95 %, binomial std 1.3 % at 300 runs.
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
