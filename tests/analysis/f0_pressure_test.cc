// The resonance at the reference clamp pressure (analysis/qc/f0_pressure.h): its value by hand,
// the regression that decides whether it is used, and teaching through TeachLimits: declared
// only when the golden units' f0 follows their pressure, taking the f0 lower bound's share, and
// catching a soft rotor that the raw f0 limit lets through.
#include "analysis/qc/f0_pressure.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "analysis/qc/measurement_names.h"
#include "analysis/qc/teach.h"

namespace eol::analysis {
namespace {

const std::string kF0(names::kResonanceFHz);
const std::string kF0p(names::kResonanceFRefPressureHz);
const std::string kP(names::kClampPressureBar);

// Good units: pressure N(5.5, 0.3) bar, ln f0 = ln 390 + slope ln(p / 5.5) + N(0, rest).
std::vector<std::pair<double, double>> Units(int n, double slope, double rest, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<std::pair<double, double>> out;
  for (int i = 0; i < n; ++i) {
    const double p = 5.5 + 0.3 * g(rng);
    out.emplace_back(390.0 * std::exp(slope * std::log(p / 5.5) + rest * g(rng)), p);
  }
  return out;
}

TEST(F0Pressure, ValueAndSigmaByHand) {
  const F0PressureDefinition d{0.1, 5.0};
  std::map<std::string, Estimate> v = {{kF0, {400.0, 0.04}}};
  const auto e = F0AtRefPressure(v, 6.0, d);
  ASSERT_TRUE(e.has_value());
  EXPECT_NEAR(e->value, 400.0 * std::pow(5.0 / 6.0, 0.1), 1e-9);
  EXPECT_NEAR(e->sigma, 0.04 * std::pow(5.0 / 6.0, 0.1), 1e-12);
  // No pressure, a pressure of zero, or no f0: left out (a declared limit then judges ERROR).
  EXPECT_FALSE(F0AtRefPressure(v, std::nullopt, d).has_value());
  EXPECT_FALSE(F0AtRefPressure(v, 0.0, d).has_value());
  EXPECT_FALSE(F0AtRefPressure({}, 6.0, d).has_value());
  AddF0AtRefPressure(v, std::nullopt, d);
  EXPECT_EQ(v.count(kF0p), 0u);
  AddF0AtRefPressure(v, 6.0, d);
  EXPECT_EQ(v.count(kF0p), 1u);
  std::string why;
  EXPECT_FALSE((F0PressureDefinition{0.0, 5.0}).IsValid(&why));
  EXPECT_NE(why.find("exponent"), std::string::npos);
  EXPECT_FALSE((F0PressureDefinition{0.6, 5.0}).IsValid(&why));
  EXPECT_FALSE((F0PressureDefinition{0.1, std::nan("")}).IsValid(&why));
  EXPECT_NE(why.find("pressure_ref_bar"), std::string::npos);
}

TEST(F0Pressure, SignificantSlopeIsUsedAndTakesTheClampsShareOut) {
  // The independent generator's figures: slope 0.114, f0 spread 1.06 % of which 0.85 % is not
  // the pressure's; 40 golden units.
  const F0PressureFit fit = TeachF0Pressure(Units(40, 0.114, 0.0085, 7));
  ASSERT_TRUE(fit.definition.has_value()) << fit.note;
  EXPECT_NEAR(fit.slope, 0.114, 3.0 * fit.slope_sigma);
  EXPECT_GE(fit.t, kF0PressureMinT);
  EXPECT_LT(fit.spread_after_pct, fit.spread_before_pct);
  EXPECT_NEAR(fit.definition->pressure_ref_bar, 5.5, 0.15);
  EXPECT_EQ(fit.note.rfind("used:", 0), 0u) << fit.note;
}

TEST(F0Pressure, NoSlopeNoVariationOrTooFewUnitsAreNotUsed) {
  // A fixture whose f0 does not follow the pressure: not used in at least 98 of 100 draws.
  int used = 0;
  for (unsigned seed = 0; seed < 100; ++seed)
    used += TeachF0Pressure(Units(40, 0.0, 0.0085, 100 + seed)).definition.has_value();
  EXPECT_LE(used, 2);
  std::vector<std::pair<double, double>> same = {{390.0, 5.5}, {391.0, 5.5}, {389.0, 5.5}};
  const F0PressureFit flat = TeachF0Pressure(same);
  EXPECT_FALSE(flat.definition.has_value());
  EXPECT_NE(flat.note.find("did not vary"), std::string::npos) << flat.note;
  EXPECT_FALSE(TeachF0Pressure({{390.0, 5.0}, {391.0, 6.0}}).definition.has_value());
  // A negative slope (f0 falling with pressure) is not the clamp's physics: not used.
  EXPECT_FALSE(TeachF0Pressure(Units(40, -0.114, 0.0085, 8)).definition.has_value());
  EXPECT_THROW(TeachF0Pressure({{390.0, 5.0}, {391.0, -1.0}, {392.0, 6.0}}), std::invalid_argument);
}

std::vector<GoldenUnit> Golden(const std::vector<std::pair<double, double>>& units,
                               bool with_pressure) {
  std::vector<GoldenUnit> out;
  for (std::size_t i = 0; i < units.size(); ++i) {
    GoldenUnit u{"g" + std::to_string(i), {{kF0, units[i].first}}, {}};
    if (with_pressure) u.values[kP] = units[i].second;
    out.push_back(u);
  }
  return out;
}

MeasurementSpec F0Limit() {
  MeasurementSpec s;
  s.name = kF0;
  s.unit = "Hz";
  s.limit.lo = 300.0;
  s.limit.hi = 500.0;
  return s;
}

TEST(F0Pressure, TeachDeclaresItAndItCatchesWhatTheRawLimitMisses) {
  TeachOptions o;
  o.mask_segments = 0;
  const auto units = Units(200, 0.114, 0.0085, 9);
  const TeachSummary s = TeachLimits({F0Limit()}, Golden(units, true), o);
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_TRUE(s.f0_pressure.definition.has_value()) << s.f0_pressure.note;
  ASSERT_EQ(s.limits.size(), 2u);
  EXPECT_EQ(s.limits[1].name, kF0p);
  ASSERT_TRUE(s.limits[1].limit.lo.has_value());
  EXPECT_FALSE(s.limits[1].limit.hi.has_value());
  // f0 keeps plausibility bounds; the normalised one carries the defect share.
  for (const TaughtBound& b : s.taught_bounds) {
    if (b.statistic == kF0) {
      EXPECT_FALSE(b.defect_side) << (b.lo ? "lo" : "hi");
    }
    if (b.statistic == kF0p) {
      EXPECT_TRUE(b.defect_side && b.lo);
    }
  }
  // A soft rotor 3.2 % low at the highest pressure of the line: above the raw f0 limit with
  // its plausibility share, below the normalised one.
  const double p = 6.1, f0 = 390.0 * std::exp(0.114 * std::log(p / 5.5) - 0.032);
  std::map<std::string, Estimate> v = {{kF0, {f0, 0.0}}};
  AddF0AtRefPressure(v, p, *s.f0_pressure.definition);
  EXPECT_GT(f0, *s.limits[0].limit.lo);
  EXPECT_LT(v.at(kF0p).value, *s.limits[1].limit.lo);

  // Without the pressure on every golden unit nothing changes, and a limit on the normalised
  // resonance declared by an earlier teaching is dropped.
  MeasurementSpec old = F0Limit();
  old.name = kF0p;
  old.limit.hi.reset();
  std::vector<GoldenUnit> mixed = Golden(units, true);
  mixed[3].values.erase(kP);
  const TeachSummary without = TeachLimits({F0Limit(), old}, mixed, o);
  ASSERT_TRUE(without.usable) << without.message;
  EXPECT_FALSE(without.f0_pressure.definition.has_value());
  EXPECT_NE(without.f0_pressure.note.find("g3"), std::string::npos) << without.f0_pressure.note;
  ASSERT_EQ(without.limits.size(), 1u);
  EXPECT_EQ(without.limits[0].name, kF0);
  for (const TaughtBound& b : without.taught_bounds) {
    if (b.statistic == kF0 && b.lo) {
      EXPECT_TRUE(b.defect_side);
    }
  }
}

TEST(F0Pressure, BondIndexWeighsTheNormalisedResonanceWhenItIsUsed) {
  TeachOptions o;
  o.mask_segments = 0;
  std::vector<GoldenUnit> golden = Golden(Units(100, 0.114, 0.0085, 10), true);
  std::mt19937 rng(11);
  std::normal_distribution<double> g(0.0, 0.08);
  for (GoldenUnit& u : golden)
    u.values[std::string(names::kMotionalResidueOhmPerS)] = 25.0 * std::exp(g(rng));
  MeasurementSpec index;
  index.name = std::string(names::kBondIndexPct);
  index.limit.hi = 1e9;
  const TeachSummary s = TeachLimits({F0Limit(), index}, golden, o);
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_TRUE(s.bond_index.has_value());
  EXPECT_EQ(s.bond_index->f0_name, kF0p);
  for (GoldenUnit& u : golden) u.values.erase(kP);
  const TeachSummary raw = TeachLimits({F0Limit(), index}, golden, o);
  ASSERT_TRUE(raw.bond_index.has_value());
  EXPECT_EQ(raw.bond_index->f0_name, kF0);
  // Less f0 spread among good units: the discriminant weighs f0 more.
  EXPECT_GT(s.bond_index->f0_exponent, raw.bond_index->f0_exponent);
}

}  // namespace
}  // namespace eol::analysis
