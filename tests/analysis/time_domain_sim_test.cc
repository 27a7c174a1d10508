// The time-domain simulator (analysis/sim/time_domain.h) against the frequency-domain
// steady state (analysis/sim/steady_state.h, bench_circuit.h) of the same clamped motor on a
// multisine: after the transient the streams agree to ~1e-10 of their peak.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "analysis/model/rotor_chain.h"
#include "analysis/signal/fft.h"
#include "analysis/signal/multisine.h"
#include "analysis/sim/time_domain.h"

namespace eol::analysis {
namespace {

ClampedMotor TenPoleMotor(const RotorChainParams& rotor = {}) {
  ClampedMotor m;
  m.r_ohm = 0.5;
  m.l_h = 2e-3;
  m.transmission_nm_per_a = 0.05;
  m.chain = BuildRotorChain(rotor);
  return m;
}

Excitation Multisine() {
  MultisineOptions o;  // 200-800 Hz, 1 Hz, 8 kHz, 2 V peak: the recipe's excitation
  return DesignMultisine(o);
}

double MaxAbsDiff(const double* a, const std::vector<double>& b) {
  double m = 0.0;
  for (std::size_t t = 0; t < b.size(); ++t) m = std::max(m, std::abs(a[t] - b[t]));
  return m;
}
std::string Sci(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}
double MaxAbs(const std::vector<double>& x) {
  double m = 0.0;
  for (double v : x) m = std::max(m, std::abs(v));
  return m;
}

TEST(BalancedExp, MatchesClosedFormOfAStiffOscillator) {
  // x'' = -w^2 x as [x; v]: exp([[0, t], [-w^2 t, 0]]) = [[cos, sin/w], [-w sin, cos]] (wt).
  const double w = 2 * std::numbers::pi * 700.0, t = 1.25e-4;
  Eigen::Matrix2d m;
  m << 0.0, t, -w * w * t, 0.0;
  const Eigen::MatrixXd e = BalancedExp(m);
  EXPECT_NEAR(e(0, 0), std::cos(w * t), 1e-15);
  EXPECT_NEAR(e(0, 1) * w, std::sin(w * t), 1e-15);
  EXPECT_NEAR(e(1, 0) / w, -std::sin(w * t), 1e-15);
}

class TimeDomainVsSteadyState : public ::testing::TestWithParam<bool> {};

TEST_P(TimeDomainVsSteadyState, AgreeAfterTheTransient) {
  RotorChainParams rotor;
  if (GetParam()) rotor.soft_magnets = {2};  // an asymmetric chain too
  const ClampedMotor motor = TenPoleMotor(rotor);
  const Excitation ex = Multisine();
  TimeDomainOptions opt;
  opt.circuit.amplifier_output_ohm = 0.05;
  opt.circuit.shunt_ohm = 0.1;
  const std::size_t n = ex.period_samples;
  const Recording rec = SimulateRecording(motor, opt, ex.Repeat(3), n, ChannelNoise{});

  const ChannelSamples ss = SteadyStatePeriod([&](double f) { return motor.Impedance(f); },
                                              opt.circuit, ex.period_v, ex.sample_rate_hz);
  // The second period (1 s after the start: the slowest mode has decayed by e^-20).
  const double i_err = MaxAbsDiff(rec.current_a.data() + n, ss.current_a) / MaxAbs(ss.current_a);
  const double u_err = MaxAbsDiff(rec.voltage_v.data() + n, ss.voltage_v) / MaxAbs(ss.voltage_v);
  EXPECT_LT(i_err, 1e-8);  // seen: 1.7e-10
  EXPECT_LT(u_err, 1e-8);  // seen: 1.0e-11
  // The first period holds the start transient: far from the steady state.
  EXPECT_GT(MaxAbsDiff(rec.current_a.data(), ss.current_a) / MaxAbs(ss.current_a), 1e-3);
  RecordProperty("current_rel_error", Sci(i_err));
  RecordProperty("voltage_rel_error", Sci(u_err));
}

INSTANTIATE_TEST_SUITE_P(Rotor, TimeDomainVsSteadyState, ::testing::Values(false, true));

// U/I on the excited lines of one steady-state period of the simulated recording.
std::vector<std::complex<double>> LineRatio(const Recording& rec, const Excitation& ex,
                                            std::size_t period) {
  const RealFft fft(ex.period_samples);
  const auto u = fft.Forward(rec.voltage_v.data() + period * ex.period_samples);
  const auto i = fft.Forward(rec.current_a.data() + period * ex.period_samples);
  std::vector<std::complex<double>> z;
  for (std::size_t k : ex.lines) z.push_back(u[k] / i[k]);
  return z;
}

TEST(TimeDomain, BandLimitedHoldGivesTheMotorImpedanceZeroOrderHoldSkewsIt) {
  const ClampedMotor motor = TenPoleMotor();
  const Excitation ex = Multisine();
  const auto freq = ex.LineFrequenciesHz();
  for (InputHold hold : {InputHold::kBandLimited, InputHold::kZeroOrder}) {
    TimeDomainOptions opt;
    opt.hold = hold;
    opt.circuit.shunt_ohm = 0.1;
    const Recording rec =
        SimulateRecording(motor, opt, ex.Repeat(3), ex.period_samples, ChannelNoise{});
    const auto z = LineRatio(rec, ex, 1);
    double worst = 0.0, worst_re = 0.0;
    for (std::size_t k = 0; k < z.size(); ++k) {
      const std::complex<double> truth = motor.Impedance(freq[k]);
      worst = std::max(worst, std::abs(z[k] - truth) / std::abs(truth));
      worst_re = std::max(worst_re, std::abs(z[k].real() - truth.real()));
    }
    if (hold == InputHold::kBandLimited) {
      EXPECT_LT(worst, 1e-6);
    } else {
      // Half a sample of skew: Re Z off by about w^2 L Ts / 2 ~ 3 ohm at 800 Hz.
      EXPECT_GT(worst_re, 1.0);
    }
  }
}

TEST(TimeDomain, StepsContinueAcrossCallsAndResetReturnsToRest) {
  const ClampedMotor motor = TenPoleMotor();
  const Excitation ex = Multisine();
  const std::vector<double> u = ex.Repeat(1);
  TimeDomainSimulator sim(motor, TimeDomainOptions{});
  std::vector<double> v1(u.size()), i1(u.size()), v2(u.size()), i2(u.size());
  sim.Run(u, 0, u.size(), v1.data(), i1.data());
  sim.Reset();
  sim.Run(u, 0, 1000, v2.data(), i2.data());
  sim.Run(u, 1000, u.size(), v2.data() + 1000, i2.data() + 1000);
  EXPECT_EQ(i1, i2);
  EXPECT_EQ(v1, v2);
}

TEST(TimeDomain, NoiseOnBothChannels) {
  const ClampedMotor motor = TenPoleMotor();
  const std::vector<double> silence(20000, 0.0);
  const Recording rec =
      SimulateRecording(motor, TimeDomainOptions{}, silence, 0, ChannelNoise{2e-3, 1e-3, 5});
  auto rms = [](const std::vector<double>& x) {
    double s = 0.0;
    for (double v : x) s += v * v;
    return std::sqrt(s / static_cast<double>(x.size()));
  };
  EXPECT_NEAR(rms(rec.voltage_v), 2e-3, 0.05e-3);
  EXPECT_NEAR(rms(rec.current_a), 1e-3, 0.025e-3);
}

TEST(TimeDomain, InvalidOptionsAreNamed) {
  TimeDomainOptions opt;
  opt.hold_points = 7;
  std::string why;
  EXPECT_FALSE(opt.IsValid(&why));
  EXPECT_NE(why.find("hold_points"), std::string::npos);
  EXPECT_THROW(TimeDomainSimulator(TenPoleMotor(), opt), std::invalid_argument);
}

}  // namespace
}  // namespace eol::analysis
