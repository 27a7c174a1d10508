// Defect detectability (analysis/qc/detectability.h): in the default fixture every magnet
// poorly cemented is separable; a class the fixture hides is flagged with remedies carrying
// numbers, and the same class is not flagged when the clamp is stiff enough.
#include "analysis/qc/detectability.h"

#include <gtest/gtest.h>

#include <cmath>

namespace eol::analysis {
namespace {

DetectabilityOptions Options(double fixture_scale) {
  DetectabilityOptions o;
  o.rotor.fixture->stiffness_nm_per_rad *= fixture_scale;
  o.rotor.fixture->damping_nms_per_rad *= fixture_scale;
  o.fit.f0_min_hz = 250.0;
  o.fit.f0_max_hz = 780.0;
  o.fit.q_min = 5.0;
  o.fit.q_max = 500.0;
  // Good-unit spread of a production line (about the production bench's).
  o.unit_spread = {{"resonance_f_hz", 4.5}, {"resonance_q", 5.0}, {"winding_r_ohm", 0.01}};
  return o;
}

const DefectPrediction& Find(const DetectabilitySummary& s, const std::string& name) {
  for (const auto& c : s.classes)
    if (c.defect == name) return c;
  static DefectPrediction none;
  ADD_FAILURE() << "no class " << name;
  return none;
}

TEST(Detectability, AllSoftIsSeparableInTheDefaultFixture) {
  const DetectabilitySummary s = PredictDetectability(Options(1.0));
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_NEAR(s.f0_good_hz, 390.0, 1.0);
  EXPECT_EQ(s.classes.size(), 4u + 5u);
  const DefectPrediction& all = Find(s, "all_soft");
  EXPECT_TRUE(all.separable) << all.best << " " << all.best_separation;
  EXPECT_LT(all.f0_hz, 375.0);
  EXPECT_GT(all.curve_separation, 100.0);
  EXPECT_TRUE(all.remedies.empty());
}

TEST(Detectability, SoftFixtureHidesAClassAndSaysWhatFixesIt) {
  // A fixture at 0.6 of the default (the good rotor rings near 321 Hz).
  const DetectabilitySummary soft = PredictDetectability(Options(0.6));
  ASSERT_TRUE(soft.usable) << soft.message;
  EXPECT_NEAR(soft.f0_good_hz, 321.0, 3.0);
  const DefectPrediction& weak = Find(soft, "weak_bonds:0.1");
  EXPECT_FALSE(weak.separable) << weak.best << " " << weak.best_separation;
  ASSERT_GE(weak.remedies.size(), 2u);
  bool clamp = false, longer = false;
  for (const std::string& r : weak.remedies) {
    clamp = clamp || r.find("stiffer clamp: k_fixture >= ") != std::string::npos;
    longer = longer || r.find("longer measurement: ") != std::string::npos;
  }
  EXPECT_TRUE(clamp && longer) << weak.remedies[0] << " | " << weak.remedies[1];
  // A bond at 0.9 of its stiffness: hidden by the good units' own spread, whatever is done.
  const DefectPrediction& slight = Find(soft, "weak_bonds:0.9");
  EXPECT_FALSE(slight.separable);
  bool hopeless = false;
  for (const std::string& r : slight.remedies)
    hopeless = hopeless || r.find("cannot separate it") != std::string::npos;
  EXPECT_TRUE(hopeless);
  // The recommended limit sits on the defect's side of the good value.
  for (const auto& m : weak.measurements) EXPECT_EQ(m.limit_is_lo, m.defect < m.good) << m.name;
}

TEST(Detectability, StiffClampSeparatesWhatTheSoftOneHides) {
  const DetectabilitySummary soft = PredictDetectability(Options(0.6));
  const DetectabilitySummary stiff = PredictDetectability(Options(20.0));
  ASSERT_TRUE(soft.usable && stiff.usable) << soft.message << stiff.message;
  const DefectPrediction& s = Find(soft, "weak_bonds:0.1");
  const DefectPrediction& t = Find(stiff, "weak_bonds:0.1");
  EXPECT_FALSE(s.separable) << s.best << " " << s.best_separation;
  EXPECT_TRUE(t.separable) << t.best << " " << t.best_separation;
  EXPECT_GT(t.best_separation, s.best_separation);
}

// Model POD against the bond stiffness loss: the bond sits in series with the bridges and the
// fixture, so f0 hardly moves until most of the bond is lost. Mild losses are invisible (POD at
// the limit's false-call level), all ten bonds are found from a loss of 0.9-0.96, and the
// a90 of one magnet is never below that of all ten.
TEST(Detectability, ModelPodRisesOnlyForSevereLoss) {
  const DetectabilitySummary s = PredictDetectability(Options(1.0));
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_EQ(s.pod.size(), 2u);
  const ModelPod& one = s.pod[0];
  const ModelPod& all = s.pod[1];
  ASSERT_EQ(all.name, "all_magnets");
  ASSERT_EQ(all.points.size(), DetectabilityOptions{}.pod_losses.size());
  EXPECT_LT(all.points.front().pod, 0.01);  // loss 0.2
  EXPECT_GE(all.points.back().pod, 0.9);    // loss 0.99
  EXPECT_GT(all.a90, 0.9);
  EXPECT_LT(all.a90, 0.96);
  // Beyond a90 POD stays at or above 0.9 (the reading of a90).
  for (const ModelPod* m : {&one, &all})
    for (const ModelPodPoint& p : m->points)
      EXPECT_TRUE(p.loss < m->a90 || p.pod >= 0.9) << m->name << " " << p.loss << " " << p.pod;
  EXPECT_GE(one.a90, all.a90);
  // f0 falls with the loss (all ten soft).
  EXPECT_LT(all.points.back().f0_hz, all.points.front().f0_hz - 20.0);
}

// a90/95 from the spread's sampling error: with the spread from 40 golden units every spread
// is taken at its 95 % upper bound, sqrt(39 / chi2_39(0.05)) = sqrt(39 / 25.6954) = 1.23199
// times (chi-square table); the lower POD equals the POD of a run with the spreads so scaled.
TEST(Detectability, ModelA9095TakesTheSpreadAtItsUpperBound) {
  DetectabilityOptions o = Options(1.0);
  const DetectabilitySummary given = PredictDetectability(o);
  ASSERT_TRUE(given.usable) << given.message;
  EXPECT_TRUE(std::isnan(given.pod[1].a90_95));  // not a sample: no confidence bound
  o.spread_units = 40;
  const DetectabilitySummary sampled = PredictDetectability(o);
  ASSERT_TRUE(sampled.usable) << sampled.message;
  DetectabilityOptions wide = Options(1.0);
  for (auto& [name, spread] : wide.unit_spread) spread *= std::sqrt(39.0 / 25.6954);
  const DetectabilitySummary upper = PredictDetectability(wide);
  ASSERT_TRUE(upper.usable) << upper.message;
  for (std::size_t c = 0; c < 2; ++c) {
    const ModelPod& p = sampled.pod[c];
    EXPECT_DOUBLE_EQ(p.a90, given.pod[c].a90) << p.name;
    EXPECT_NEAR(p.a90_95, upper.pod[c].a90, 1e-4) << p.name;
    EXPECT_GE(p.a90_95, p.a90) << p.name;
    for (std::size_t k = 0; k < p.points.size(); ++k)
      EXPECT_NEAR(p.points[k].pod_lower, upper.pod[c].points[k].pod, 1e-4)
          << p.name << " " << p.points[k].loss;
  }
}

TEST(Detectability, InvalidOptionsAreNamed) {
  DetectabilityOptions o = Options(1.0);
  o.rotor.fixture.reset();
  const DetectabilitySummary s = PredictDetectability(o);
  EXPECT_FALSE(s.usable);
  EXPECT_NE(s.message.find("fixture must be set"), std::string::npos) << s.message;
}

}  // namespace
}  // namespace eol::analysis
