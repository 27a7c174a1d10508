// The clamped rotor chain (analysis/model/rotor_chain.h, torsional_chain.h) against the
// paper's numbers (analysis/README.md 2): 706 Hz rigid, 529 Hz rigid with every bond poor, 390 Hz
// in the default fixture; one soft magnet gives a local mode (a split peak on a rigid fixture).
#include "analysis/model/torsional_chain.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "analysis/model/rotor_chain.h"

namespace eol::analysis {
namespace {

RotorChainParams Rigid() {
  RotorChainParams p;
  p.fixture.reset();
  return p;
}

RotorChainParams AllSoft(RotorChainParams p) {
  for (int i = 0; i < p.magnets; ++i) p.soft_magnets.push_back(i);
  return p;
}

// The modes the torque excites: participation above 1e-6 of the largest.
std::vector<ChainMode> Visible(const TorsionalChain& chain) {
  std::vector<ChainMode> all = chain.Modes(), out;
  double top = 0.0;
  for (const auto& m : all) top = std::max(top, m.participation);
  for (const auto& m : all)
    if (m.participation > 1e-6 * top) out.push_back(m);
  return out;
}

TEST(RotorChain, CalibratedToThePaper) {
  EXPECT_NEAR(BuildRotorChain(Rigid()).Modes()[0].f_hz, 706.0, 0.7);
  EXPECT_NEAR(BuildRotorChain(AllSoft(Rigid())).Modes()[0].f_hz, 529.0, 0.5);
  EXPECT_NEAR(BuildRotorChain(RotorChainParams{}).Modes()[0].f_hz, 390.0, 0.4);
  // The default fixture turns the poorly cemented rotor's 529 Hz into about 366 Hz.
  EXPECT_NEAR(BuildRotorChain(AllSoft(RotorChainParams{})).Modes()[0].f_hz, 366.0, 1.0);
  // Damping: Q ~ 60 on the rigid mode, ~ 54 for a good rotor in the default fixture.
  EXPECT_NEAR(BuildRotorChain(Rigid()).Modes()[0].q, 60.0, 1.0);
  EXPECT_NEAR(BuildRotorChain(RotorChainParams{}).Modes()[0].q, 54.4, 1.0);
}

TEST(RotorChain, SymmetricRotorShowsOneMode) {
  // Identical magnets: only the modes where all magnets move together are excited.
  const auto visible = Visible(BuildRotorChain(RotorChainParams{}));
  ASSERT_GE(visible.size(), 1u);
  EXPECT_NEAR(visible[0].f_hz, 390.0, 0.4);
  for (std::size_t n = 1; n < visible.size(); ++n) EXPECT_GT(visible[n].f_hz, 2000.0);
  // All of the torque's inertia is in the first mode within a few percent: 1/g ~ J_rim.
  EXPECT_GT(visible[0].participation, 0.9 / 1.0e-4);
}

TEST(RotorChain, OneSoftMagnetSplitsThePeakOnARigidFixture) {
  RotorChainParams p = Rigid();
  p.soft_magnets = {3};
  const TorsionalChain chain = BuildRotorChain(p);
  const auto visible = Visible(chain);
  ASSERT_GE(visible.size(), 2u);
  const double t = 0.05;
  EXPECT_NEAR(visible[0].f_hz, 567.3, 2.0);
  EXPECT_NEAR(visible[1].f_hz, 723.8, 2.0);
  // Two peaks of comparable height in the band, no third one below 1 kHz.
  const double rp0 = visible[0].RpOhm(t), rp1 = visible[1].RpOhm(t);
  EXPECT_GT(rp0, 0.3 * rp1);
  EXPECT_GT(rp1, 0.3 * rp0);
  if (visible.size() > 2) {
    EXPECT_GT(visible[2].f_hz, 1000.0);
  }
}

TEST(RotorChain, OneSoftMagnetInTheDefaultFixtureIsMostlyHidden) {
  RotorChainParams p;
  p.soft_magnets = {0};
  const auto visible = Visible(BuildRotorChain(p));
  ASSERT_GE(visible.size(), 2u);
  EXPECT_NEAR(visible[0].f_hz, 386.8, 1.0);  // -0.8 %: inside the production spread
  EXPECT_NEAR(visible[1].f_hz, 587.7, 2.0);  // the local mode
  EXPECT_LT(visible[1].RpOhm(0.05), 0.05 * visible[0].RpOhm(0.05));
}

TEST(RotorChain, MobilityMatchesTheModalSum) {
  // Z_mot from the direct solve equals the sum of the modal parallel R-L-C terms near each
  // lightly damped peak (proportional-damping approximation, a few percent off-peak).
  ClampedMotor motor;
  motor.r_ohm = 0.5;
  motor.l_h = 2e-3;
  motor.transmission_nm_per_a = 0.05;
  motor.chain = BuildRotorChain(RotorChainParams{});
  const auto terms = motor.ModalTerms();
  const double f0 = terms[0].f0_hz;
  const std::complex<double> direct = motor.Impedance(f0);
  const std::complex<double> background(motor.r_ohm, 2 * std::numbers::pi * f0 * motor.l_h);
  std::complex<double> modal = background;
  for (const auto& m : terms) modal += m.At(f0) - background;
  EXPECT_LT(std::abs(direct - modal), 0.01 * terms[0].rp_ohm);
  // At f0 the real part peaks at R + Rp.
  EXPECT_NEAR(direct.real(), motor.r_ohm + terms[0].rp_ohm, 0.02 * terms[0].rp_ohm);
}

TEST(TorsionalChain, SingleModeMatchesClampedRotor) {
  ClampedRotor rotor;
  rotor.inertia_kg_m2 = 1e-4;
  rotor.k_rotor_nm_per_rad = StiffnessForFrequency(1e-4, 706.0);
  rotor.k_fixture_nm_per_rad = 900.0;
  rotor.q = 50.0;
  rotor.transmission_nm_per_a = 0.05;
  ClampedMotor motor{0.5, 2e-3, 0.05, SingleModeChain(rotor)};
  const MotionalImpedance z = rotor.Electrical(0.5, 2e-3);
  for (double f : {100.0, 350.0, z.f0_hz, 500.0, 2000.0})
    EXPECT_LT(std::abs(motor.Impedance(f) - z.At(f)), 1e-12 * std::abs(z.At(f))) << f;
  const auto modes = motor.chain.Modes();
  ASSERT_EQ(modes.size(), 1u);
  EXPECT_NEAR(modes[0].f_hz, z.f0_hz, 1e-9 * z.f0_hz);
  EXPECT_NEAR(modes[0].q, 50.0, 1e-9);
  EXPECT_NEAR(modes[0].RpOhm(0.05), z.rp_ohm, 1e-9 * z.rp_ohm);
  // The residue Rp w0 / Q is T^2 / J whatever the stiffness and damping.
  EXPECT_NEAR(z.ResidueOhmPerS(), 0.05 * 0.05 / 1e-4, 1e-9 * z.ResidueOhmPerS());
}

// The first mode's residue T^2 / J_eff (motor_model.h) against its frequency: softer bonds
// let less inertia follow the magnets, so the residue rises many times faster than f0 falls,
// while a stiffer or softer clamp moves f0 and leaves the residue nearly where it was.
TEST(RotorChain, ResidueRisesWithSoftBondsAndIgnoresTheClamp) {
  auto first = [](const RotorChainParams& p) {
    ClampedMotor motor{0.5, 2e-3, 0.05, BuildRotorChain(p)};
    return motor.ModalTerms().at(0);
  };
  const RotorChainParams good;
  const MotionalImpedance g = first(good);
  const MotionalImpedance soft = first(AllSoft(good));
  RotorChainParams stiff_clamp = good;
  stiff_clamp.fixture->stiffness_nm_per_rad *= 1.2;
  const MotionalImpedance clamp = first(stiff_clamp);
  const double df_soft = 1.0 - soft.f0_hz / g.f0_hz;
  const double da_soft = soft.ResidueOhmPerS() / g.ResidueOhmPerS() - 1.0;
  EXPECT_GT(df_soft, 0.05);           // 390 -> 366 Hz
  EXPECT_GT(da_soft, 8.0 * df_soft);  // +73 %
  const double df_clamp = clamp.f0_hz / g.f0_hz - 1.0;
  const double da_clamp = std::abs(clamp.ResidueOhmPerS() / g.ResidueOhmPerS() - 1.0);
  EXPECT_GT(df_clamp, 0.03);
  EXPECT_LT(da_clamp, 0.5 * df_clamp);
  // Good rotor: close to T^2 over the whole rotor's inertia (1.05e-4 kg m^2 with the clamp).
  EXPECT_NEAR(g.ResidueOhmPerS(), 0.05 * 0.05 / 1.05e-4, 0.15 * 0.05 * 0.05 / 1.05e-4);
}

TEST(TorsionalChain, InvalidChainsAreNamed) {
  std::string why;
  TorsionalChain floating;
  floating.AddInertia("free", 1e-4);
  floating.SetTorqueWeight(0, 1.0);
  EXPECT_FALSE(floating.IsValid(&why));
  EXPECT_NE(why.find("not held to ground"), std::string::npos) << why;

  RotorChainParams p;
  p.soft_magnets = {10};
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("soft magnet 10"), std::string::npos) << why;
  EXPECT_THROW(BuildRotorChain(p), std::invalid_argument);
}

TEST(RotorChain, Defects) {
  std::vector<int> soft;
  std::string why;
  ASSERT_TRUE(SoftMagnetsForDefect("none", 10, &soft, &why));
  EXPECT_TRUE(soft.empty());
  ASSERT_TRUE(SoftMagnetsForDefect("one_soft_magnet", 10, &soft, &why));
  EXPECT_EQ(soft, std::vector<int>{0});
  ASSERT_TRUE(SoftMagnetsForDefect("all_soft", 10, &soft, &why));
  EXPECT_EQ(soft.size(), 10u);
  ASSERT_TRUE(SoftMagnetsForDefect("partial:0.3", 10, &soft, &why));
  EXPECT_EQ(soft, (std::vector<int>{0, 1, 2}));
  EXPECT_FALSE(SoftMagnetsForDefect("partial:1.5", 10, &soft, &why));
  EXPECT_NE(why.find("[0, 1]"), std::string::npos) << why;
  EXPECT_FALSE(SoftMagnetsForDefect("cracked", 10, &soft, &why));
  EXPECT_NE(why.find("known: none, one_soft_magnet"), std::string::npos) << why;
}

}  // namespace
}  // namespace eol::analysis
