// station/daemon/recipe_design.h: recipes proposed from the shipped motor files (the ten-pole motor
// and the eight-pole second type), their calibration to good units, and every refusal.
#include "station/daemon/recipe_design.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "analysis/qc/measurement_names.h"
#include "station/daemon/qc_service.h"

namespace eol::station {
namespace {

namespace names = analysis::names;

io::MotorSpec Motor(const std::string& name) {
  return io::LoadMotorJson(std::string(EOL_SOURCE_DIR) + "/recipes/motors/" + name + ".json");
}

TEST(RecipeDesign, TenPoleMotorGivesTheShippedRecipesBandAndDirection) {
  const RecipeBasis b = BasisFromMotor(Motor("pmsm-10pole"));
  const RecipeProposal p = ProposeRecipe(b, {}, "ten");
  for (const std::string& n : p.notes) std::cout << n << "\n";
  const Recipe r = ParseRecipe(p.recipe, "proposal");
  EXPECT_NEAR(b.nominal.f0_hz, 390.0, 1.0);
  EXPECT_NEAR(r.excitation.f_lo_hz, 190.0, 1e-9);
  EXPECT_NEAR(r.excitation.f_hi_hz, 790.0, 1e-9);
  EXPECT_LT(r.analysis.fit.f0_min_hz, b.f0_all_soft_hz);
  EXPECT_GT(r.analysis.fit.f0_max_hz, 1.5 * b.nominal.f0_hz);
  // The chain's own direction, about the ten-pole motor's 12 (bond_index.h).
  ASSERT_TRUE(r.bond_index.has_value());
  EXPECT_NEAR(r.bond_index->residue_to_f0, 11.1, 1.0);
  EXPECT_NEAR(p.required_sigma_f0_hz, 1e-3 * (b.nominal.f0_hz - b.f0_half_soft_hz), 1e-12);
  ASSERT_TRUE(r.excitation_design.has_value());
  EXPECT_LE(p.chosen.sigma_f0_hz, p.required_sigma_f0_hz * (1 + 1e-9));
  EXPECT_LT(p.chosen.record_s, 1.0);
  // The shortest record at the amplitude the current range allows (not lowered): the shipped
  // fast recipe's 7.3 V and its 0.0085 Hz.
  EXPECT_EQ(p.chosen.periods, 2u);
  EXPECT_NE(p.chosen.amplitude_limited_by, "requirement");
  EXPECT_GT(p.chosen.peak_v, 6.0);
  EXPECT_LT(r.excitation_design->sigma_f0_hz, 0.01);
  EXPECT_NEAR(r.conditions.r_ref_ohm, 0.5, 1e-12);
  EXPECT_TRUE(r.masks.empty());
  ASSERT_TRUE(r.approval.has_value());
  EXPECT_EQ(r.approval->state, "proposed");
  EXPECT_EQ(r.approval->by, "eol recipe-new");
}

TEST(RecipeDesign, SecondMotorGetsItsOwnBandReferenceAndDirection) {
  const RecipeBasis ten = BasisFromMotor(Motor("pmsm-10pole"));
  const RecipeBasis b = BasisFromMotor(Motor("pmsm-8pole-heavy"));
  const RecipeProposal p = ProposeRecipe(b, {}, "eight");
  for (const std::string& n : p.notes) std::cout << n << "\n";
  const Recipe r = ParseRecipe(p.recipe, "proposal");
  EXPECT_NEAR(b.nominal.f0_hz / ten.nominal.f0_hz, 1.5, 0.05);
  EXPECT_EQ(r.poles, 8);
  EXPECT_NEAR(r.conditions.r_ref_ohm, 1.1, 1e-12);
  EXPECT_GT(b.f0_all_soft_hz, r.analysis.fit.f0_min_hz);
  EXPECT_LT(r.excitation.f_lo_hz, r.analysis.fit.f0_min_hz);
  EXPECT_GT(r.excitation.f_hi_hz, r.analysis.fit.f0_max_hz);
  // Another chain, another direction: not the ten-pole motor's.
  EXPECT_LT(b.residue_to_f0, 6.0) << b.residue_to_f0;
  EXPECT_GT(ten.residue_to_f0, 8.0) << ten.residue_to_f0;
  EXPECT_NEAR(r.bond_index->residue_to_f0, b.residue_to_f0, 1e-12);
}

analysis::GoldenUnit Unit(const analysis::MotionalImpedance& m, double f0_scale, int i) {
  analysis::GoldenUnit u;
  u.label = "u" + std::to_string(i);
  const double wobble = 1.0 + 0.001 * (i - 2);
  u.values = {{std::string(names::kResonanceFHz), m.f0_hz * f0_scale * wobble},
              {std::string(names::kResonanceQ), m.q},
              {std::string(names::kWindingROhm), m.r_ohm * 1.1},
              {std::string(names::kWindingLH), m.l_h},
              {std::string(names::kMotionalResidueOhmPerS), m.ResidueOhmPerS()}};
  return u;
}

TEST(RecipeDesign, CalibrationMovesTheDesignToTheUnitsAndSaysWhereTheyDisagree) {
  const RecipeBasis b = BasisFromMotor(Motor("pmsm-8pole-heavy"));
  std::vector<analysis::GoldenUnit> golden;
  for (int i = 0; i < 5; ++i) golden.push_back(Unit(b.nominal, 1.08, i));
  const Calibration c = CalibrateToGolden(b, golden);
  for (const std::string& d : c.disagreements) std::cout << d << "\n";
  EXPECT_EQ(c.units, 5);
  EXPECT_NEAR(c.basis.nominal.f0_hz, 1.08 * b.nominal.f0_hz, 1e-6 * b.nominal.f0_hz);
  EXPECT_NEAR(c.basis.nominal.r_ohm, 1.1 * b.nominal.r_ohm, 1e-9);
  EXPECT_NEAR(c.basis.f0_all_soft_hz, 1.08 * b.f0_all_soft_hz, 1e-6 * b.f0_all_soft_hz);
  EXPECT_NEAR(c.basis.nominal.ResidueOhmPerS(), b.nominal.ResidueOhmPerS(), 1e-9);
  ASSERT_EQ(c.disagreements.size(), 5u);
  EXPECT_NE(c.disagreements[0].find("resonance_f_hz: design "), std::string::npos);
  EXPECT_NE(c.disagreements[0].find("(+8.0 %) DISAGREES (more than 5 %"), std::string::npos)
      << c.disagreements[0];
  EXPECT_NE(c.disagreements[2].find("(+10.0 %)"), std::string::npos) << c.disagreements[2];
  EXPECT_EQ(c.disagreements[2].find("DISAGREES"), std::string::npos) << c.disagreements[2];
  const Recipe r = ParseRecipe(ProposeRecipe(c.basis, {}, "eight").recipe, "calibrated");
  EXPECT_NEAR(r.conditions.r_ref_ohm, 1.1 * b.nominal.r_ohm, 1e-9);
  EXPECT_NEAR(r.excitation_design->nominal.f0_hz, c.basis.nominal.f0_hz, 1e-9);
}

template <typename F>
std::string Refusal(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "no refusal";
}

TEST(RecipeDesign, BadInputsAreRefusedNamingTheCause) {
  const RecipeBasis b = BasisFromMotor(Motor("pmsm-8pole-heavy"));
  RecipeNewOptions slow;
  slow.sample_rate_hz = 2000.0;
  EXPECT_NE(Refusal([&] { ProposeRecipe(b, slow, "x"); }).find("needs a sample rate of at least"),
            std::string::npos);
  RecipeNewOptions loose;
  loose.shift_fraction = 0.5;
  EXPECT_NE(Refusal([&] { ProposeRecipe(b, loose, "x"); }).find("shift_fraction must be in"),
            std::string::npos);
  RecipeNewOptions weak;
  weak.max_peak_v = 1e-4;  // no record within 60 s reaches the requirement
  const std::string weak_why = Refusal([&] { ProposeRecipe(b, weak, "x"); });
  EXPECT_NE(weak_why.find("no excitation meets the requirement"), std::string::npos) << weak_why;
  std::vector<analysis::GoldenUnit> two = {Unit(b.nominal, 1.0, 0), Unit(b.nominal, 1.0, 1)};
  EXPECT_NE(Refusal([&] { CalibrateToGolden(b, two); }).find("needs at least 3"),
            std::string::npos);
  two.push_back(Unit(b.nominal, 1.0, 2));
  two[1].values.erase(std::string(names::kMotionalResidueOhmPerS));
  EXPECT_NE(Refusal([&] {
              CalibrateToGolden(b, two);
            }).find("golden unit u1: has no positive motional_residue_ohm_per_s"),
            std::string::npos);
  RecipeBasis flat = b;
  flat.f0_half_soft_hz = flat.nominal.f0_hz;
  EXPECT_NE(Refusal([&] { ProposeRecipe(flat, {}, "x"); }).find("does not ring lower"),
            std::string::npos);
}

// The detectability model must be the recipe's motor (station/daemon/qc_service.h): the built-in
// chain is refused for the eight-pole recipe (what GET /api/detectability answers 422
// model_mismatch with), the recipe's own motor JSON is accepted, and so is the ten-pole
// recipe on the built-in chain.
TEST(RecipeDesign, DetectabilityRefusesAModelOfAnotherMotor) {
  const Recipe eight = LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-8pole-heavy.json");
  const Recipe ten = LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  const std::string why = DetectabilityModelMismatch(eight, nullptr);
  EXPECT_NE(why.find("recipe pmsm-8pole-heavy expects 588.8 Hz"), std::string::npos) << why;
  const io::MotorSpec motor = Motor("pmsm-8pole-heavy");
  EXPECT_EQ(DetectabilityModelMismatch(eight, &motor), "");
  EXPECT_EQ(DetectabilityModelMismatch(ten, nullptr), "");
  // The ten-pole recipe on the eight-pole motor is refused the other way round.
  EXPECT_NE(DetectabilityModelMismatch(ten, &motor), "");
}

}  // namespace
}  // namespace eol::station
