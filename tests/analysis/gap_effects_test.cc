// Contracts of the unmodelled-effect library (analysis/model/effects.h): every effect
// vanishes at its neutral parameters, follows its equation, and the fixture's series spring
// reproduces analysis::ClampedRotor (the simulator's fixture).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analysis/fit/resonance_fit.h"
#include "analysis/model/effects.h"
#include "analysis/sim/population.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

NominalNetwork PaperNominal() {
  MotorPopulation p;
  p.spread_inertia = p.spread_k_rotor = p.spread_k_fixture = p.spread_q = p.spread_r = p.spread_l =
      p.spread_transmission = 0.0;
  SimUnit u = DrawUnit(p, "NOMINAL", false);
  u.rotor.k_fixture_nm_per_rad = std::numeric_limits<double>::infinity();
  NominalNetwork n;
  n.motional = u.Electrical();
  n.inertia_kg_m2 = u.rotor.inertia_kg_m2;
  return n;
}

TEST(GapEffects, NamesRoundTripAndMobilityHasTwo) {
  for (int i = 0; i < kEffectKindCount; ++i) {
    const auto k = static_cast<EffectKind>(i);
    EXPECT_EQ(ParseEffectKind(ToString(k)), k);
  }
  EXPECT_FALSE(ParseEffectKind("fixture"));
  EXPECT_EQ(EffectsFor(Quantity::kImpedanceOhm).size(), static_cast<std::size_t>(kEffectKindCount));
  EXPECT_EQ(EffectsFor(Quantity::kMobility).size(), 2u);
}

TEST(GapEffects, NeutralParametersGiveTheNominal) {
  const NominalNetwork n = PaperNominal();
  const std::vector<AppliedEffect> neutral = {{EffectKind::kSeriesResistance, {0.0}},
                                              {EffectKind::kChannelDelay, {0.0}},
                                              {EffectKind::kStrayCapacitance, {0.0}},
                                              {EffectKind::kLossyInductance, {1e-15, 1e3}},
                                              {EffectKind::kSkinEffect, {0.0}},
                                              {EffectKind::kFixtureCompliance, {1e15, 0.0}},
                                              {EffectKind::kSecondMode, {500.0, 30.0, 0.0}},
                                              {EffectKind::kAdhesiveCreep, {0.0}}};
  for (double f : {200.0, 500.0, 706.0, 800.0}) {
    const Cplx z0 = n.At(f);
    EXPECT_NEAR(std::abs(EvaluateNetwork(n, neutral, f) - z0), 0.0, 1e-9 * std::abs(z0)) << f;
    for (const AppliedEffect& e : neutral) {
      const std::vector<AppliedEffect> one = {e};
      EXPECT_NEAR(std::abs(EvaluateNetwork(n, one, f) - z0), 0.0, 1e-9 * std::abs(z0))
          << ToString(e.kind) << " at " << f;
    }
  }
}

TEST(GapEffects, ElectricalEffectsFollowTheirEquations) {
  const NominalNetwork n = PaperNominal();
  const double f = 650.0;
  const Cplx s(0.0, 2.0 * std::numbers::pi * f);
  const Cplx z0 = n.At(f);
  auto eval = [&](EffectKind k, std::vector<double> p) {
    const std::vector<AppliedEffect> e = {{k, p}};
    return EvaluateNetwork(n, e, f);
  };
  EXPECT_NEAR(std::abs(eval(EffectKind::kSeriesResistance, {0.02}) - (z0 + 0.02)), 0.0, 1e-12);
  EXPECT_NEAR(std::abs(eval(EffectKind::kChannelDelay, {20e-6}) - z0 * std::exp(-s * 20e-6)), 0.0,
              1e-12);
  EXPECT_NEAR(std::abs(eval(EffectKind::kStrayCapacitance, {1e-7}) - z0 / (1.0 + s * 1e-7 * z0)),
              0.0, 1e-12);
  const double l2 = 2e-4, r2 = 3.0, corner = r2 / (2.0 * std::numbers::pi * l2);
  EXPECT_NEAR(std::abs(eval(EffectKind::kLossyInductance, {l2, corner}) -
                       (z0 - s * l2 + s * l2 * r2 / (s * l2 + r2))),
              0.0, 1e-12);
  EXPECT_NEAR(
      std::abs(eval(EffectKind::kSkinEffect, {0.5}) - (z0 + n.motional.r_ohm * 0.5 * 0.65 * 0.65)),
      0.0, 1e-12);
  const double w2 = 2.0 * std::numbers::pi * 600.0;
  EXPECT_NEAR(std::abs(eval(EffectKind::kSecondMode, {600.0, 40.0, 0.1}) -
                       (z0 + 0.1 / (1.0 + 40.0 * (s / w2 + w2 / s)))),
              0.0, 1e-12);
  // Lossy inductance: the inductance falls and the resistance rises above the corner.
  const Cplx lossy = eval(EffectKind::kLossyInductance, {l2, corner});
  EXPECT_GT(lossy.real(), z0.real());
  EXPECT_LT(lossy.imag(), z0.imag());
}

// The fixture effect with the loss that keeps Q is the simulator's fixture
// (analysis::ClampedRotor keeps Q): from the rigid 706 Hz rotor, the paper's 390 Hz, same Q.
TEST(GapEffects, FixtureComplianceReproducesTheClampedRotor) {
  const NominalNetwork n = PaperNominal();
  MotorPopulation p;
  const double kappa = p.KFixtureNmPerRad() / p.KRotorNmPerRad(false);
  const std::vector<AppliedEffect> e = {
      {EffectKind::kFixtureCompliance, {kappa, FixtureLossKeepingQ(kappa, n.motional.q)}}};
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 1.0) f.push_back(x);
  const Frf z = EvaluateNetwork(n, e, f);
  ResonanceFitOptions o;
  const FitSummary fit = FitMotionalResonance(z, o);
  ASSERT_TRUE(fit.usable) << fit.message;
  EXPECT_NEAR(fit.Model().f0_hz, p.f_fixture_hz, 0.5);
  EXPECT_NEAR(fit.Model().q, n.motional.q, 0.05 * n.motional.q);
  const auto derived = DeriveEffectParams(n, e.front());
  ASSERT_EQ(derived.size(), 2u);
  EXPECT_EQ(derived[0].name, "k_fixture_nm_per_rad");
  EXPECT_NEAR(derived[0].value / p.KFixtureNmPerRad(), 1.0, 1e-9);
  EXPECT_NEAR(derived[1].value, p.f_fixture_hz, 0.5);
}

TEST(GapEffects, CreepSoftensBelowF0AndAddsLoss) {
  const NominalNetwork n = PaperNominal();
  const std::vector<AppliedEffect> e = {{EffectKind::kAdhesiveCreep, {0.1}}};
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 1.0) f.push_back(x);
  const FitSummary fit = FitMotionalResonance(EvaluateNetwork(n, e, f), ResonanceFitOptions{});
  ASSERT_TRUE(fit.usable) << fit.message;
  // The peak stays near f0 (the compliance at f0 is C0) but is broader.
  EXPECT_NEAR(fit.Model().f0_hz, n.motional.f0_hz, 0.02 * n.motional.f0_hz);
  EXPECT_LT(fit.Model().q, 0.8 * n.motional.q);
}

TEST(GapEffects, PlausibilityBoundsNameTheParameter) {
  const NominalNetwork n = PaperNominal();
  const EffectSpec fixture = DescribeEffect(EffectKind::kFixtureCompliance, n, 200.0, 800.0);
  std::string why;
  EXPECT_TRUE(IsPlausible(fixture, {EffectKind::kFixtureCompliance, {0.44, 0.02}}, &why)) << why;
  EXPECT_FALSE(IsPlausible(fixture, {EffectKind::kFixtureCompliance, {3e6, 0.02}}, &why));
  EXPECT_NE(why.find("k_fixture_ratio"), std::string::npos) << why;
  const EffectSpec stray = DescribeEffect(EffectKind::kStrayCapacitance, n, 200.0, 800.0);
  EXPECT_EQ(stray.params[0].name, "capacitance_f");
  EXPECT_FALSE(IsPlausible(stray, {EffectKind::kStrayCapacitance, {1e-3}}, &why));
  const EffectSpec eddy = DescribeEffect(EffectKind::kLossyInductance, n, 200.0, 800.0);
  // Corner 1 Hz: far below the band, an eddy branch cannot be told from a smaller L (the
  // fit's bound keeps it at 0.1 f_lo or above).
  EXPECT_EQ(eddy.params[1].name, "corner_hz");
  EXPECT_DOUBLE_EQ(eddy.params[1].lo, 20.0);
  EXPECT_TRUE(eddy.params[1].bounded);
  EXPECT_FALSE(IsPlausible(eddy, {EffectKind::kLossyInductance, {1e-4, 1.0}}, &why));
  EXPECT_NE(why.find("corner_hz"), std::string::npos) << why;
  NominalNetwork m;
  m.quantity = Quantity::kMobility;
  m.rigid = {100.0, 10.0};
  const EffectSpec mode = DescribeEffect(EffectKind::kSecondMode, m, 11.0, 250.0);
  EXPECT_EQ(mode.params[0].name, "f_hz");
  EXPECT_EQ(mode.params[2].name, "height_rad_per_s_per_a");
}

// coupled_inertia at a node of the support against the mechanics written out (torque / angular
// velocity, analysis/README.md 1): J on the rotor spring k_r (c_r) to a node that holds J2 on k2
// (c2) and sits on the fixture spring k_f (c_f) to ground, damping stiffness-proportional, so that
// k = k_r k_f / (k_r + k_f) and x = k / k_r. Z = R + s L + T^2 / Zm.
TEST(GapEffects, CoupledInertiaAtANodeIsTheThreeSpringChain) {
  const NominalNetwork n = PaperNominal();
  const MotionalImpedance& m = n.motional;
  const double t2 = 1.0;  // T^2 only scales the mechanics: Cp = J / T^2 etc.
  const double w0 = 2.0 * std::numbers::pi * m.f0_hz;
  const double j = m.q / (w0 * m.rp_ohm) * t2, k = w0 * w0 * j, c = t2 / m.rp_ohm;
  for (double x : {0.0, 0.4, 0.8}) {
    const double mu = 0.3, f2 = 2.2 * m.f0_hz, q2 = 25.0;
    const double j2 = mu * j, w2 = 2.0 * std::numbers::pi * f2, k2 = j2 * w2 * w2;
    const double c2 = std::sqrt(k2 * j2) / q2;
    const std::vector<AppliedEffect> e = {{EffectKind::kCoupledInertia, {mu, f2, q2, x}}};
    for (double f : {100.0, 0.8 * m.f0_hz, m.f0_hz, 1.7 * m.f0_hz, f2, 3000.0}) {
      const Cplx s(0.0, 2.0 * std::numbers::pi * f);
      const Cplx branch = 1.0 / (1.0 / (k2 / s + c2) + 1.0 / (s * j2));
      Cplx zm;
      if (x == 0.0) {
        zm = s * j + k / s + c + branch;
      } else {
        const Cplx rotor_spring = (k / s + c) / x, fixture_spring = (k / s + c) / (1.0 - x);
        zm = s * j + 1.0 / (1.0 / rotor_spring + 1.0 / (fixture_spring + branch));
      }
      const Cplx expected = m.r_ohm + s * m.l_h + t2 / zm;
      EXPECT_NEAR(std::abs(EvaluateNetwork(n, e, f) - expected), 0.0, 1e-9 * std::abs(expected))
          << "x " << x << " f " << f;
    }
  }
}

// fractional_inductance: Z_L = s L (1 - b) + b L w_m^(1 - n) (j w)^n, the same |Z| as b s L at
// w_m; the match frequency free.
TEST(GapEffects, FractionalInductanceMatchesItsShareAtTheMatchFrequency) {
  const NominalNetwork n = PaperNominal();
  const double b = 0.2, order = 0.6, fm = 316.0;
  const std::vector<AppliedEffect> e = {{EffectKind::kFractionalInductance, {b, order, fm}}};
  for (double f : {50.0, fm, 1500.0}) {
    const double w = 2.0 * std::numbers::pi * f, wm = 2.0 * std::numbers::pi * fm;
    const Cplx frac = b * n.motional.l_h * std::pow(wm, 1.0 - order) * std::pow(w, order) *
                      std::polar(1.0, order * std::numbers::pi / 2.0);
    const Cplx expected = n.At(f) - Cplx(0.0, w * b * n.motional.l_h) + frac;
    EXPECT_NEAR(std::abs(EvaluateNetwork(n, e, f) - expected), 0.0, 1e-9 * std::abs(expected));
    if (f == fm) {
      EXPECT_NEAR(std::abs(frac), b * w * n.motional.l_h, 1e-9 * std::abs(frac));
    }
  }
}

}  // namespace
}  // namespace eol::analysis
