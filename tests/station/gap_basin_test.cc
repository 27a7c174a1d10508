// Which basin of an effect's likelihood is its answer (analysis/gap/effect_fit.h FitKinds), on
// a blind case of the independent generator (tests/data/gap-independent-coupled: a coupled
// second inertia at the shaft-end node, near the information limit against a fixture spring).
// Contract: the lowest-cost optimum of the coupled inertia is a narrow basin that loses on
// evidence; the fit answers the basin with the better evidence, keeps the lowest-cost one for
// the pairs, and the diagnosis then names the coupled inertia (with the lowest-cost basin it
// named the fixture spring).
// And a winding whose whole inductance is a semi-inductance
// (tests/data/gap-independent-semi-inductance): the fractional inductance's share sits at its
// bound of 1, a plausible answer.
// These cases are exact simulations plus one effect, near the information limit; the nominal is
// kept at the simulation's values here (GapOptions::calibrate = false): with it calibrated
// within the design's tolerances (issue 38) the weak coupled inertias and the eddy corner below
// the band are within J's and L's tolerances and answered `none`.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "analysis/gap/calibration.h"
#include "analysis/gap/diagnosis.h"
#include "analysis/gap/effect_fit.h"
#include "drivers/io/frf_files.h"

namespace eol {
namespace {

const std::string kCoupled = std::string(EOL_TEST_DATA_DIR) + "/gap-independent-coupled/";
const std::string kSemi = std::string(EOL_TEST_DATA_DIR) + "/gap-independent-semi-inductance/";
const std::string kEddy = std::string(EOL_TEST_DATA_DIR) + "/gap-independent-eddy/";

struct BlindCase {
  analysis::NominalNetwork nominal;
  analysis::GapUnit unit;
};

// The unit's residual form as the diagnosis chooses it (ChooseResidualForm), or as `form`.
BlindCase Load(const std::string& name, const std::string& dir = kCoupled,
               analysis::ResidualForm form = analysis::ResidualForm::kAuto) {
  BlindCase c;
  const analysis::Frf sim = io::ReadFrfCsv(dir + name + "-sim.csv.gz");
  const analysis::CalibrationSummary cal = analysis::CalibrateNominal(sim, {});
  EXPECT_TRUE(cal.usable) << cal.message;
  c.nominal = cal.nominal;
  const analysis::Frf meas = io::ReadFrfCsv(dir + name + "-meas.csv.gz");
  c.unit.name = name;
  c.unit.freq_hz = meas.freq_hz;
  c.unit.value = meas.value;
  c.unit.sigma = meas.sigma;
  c.unit.sigma_dof = 14.0;  // 8 periods
  analysis::ChooseResidualForm(c.unit, true, form);
  return c;
}

// The diagnosis with its default options, without the held-out split (not what these test).
analysis::GapSummary Diagnose(const BlindCase& c,
                              analysis::ResidualForm form = analysis::ResidualForm::kAuto) {
  analysis::GapOptions o;
  o.heldout = false;
  o.calibrate = false;  // the exact simulation's basins (kept fixed: see the top)
  o.residual_form = form;
  return analysis::DiagnoseGap(c.nominal, {c.unit}, o);
}

// The ranking's entry for `effect` (the test fails when there is none).
analysis::RankedEffect Ranked(const analysis::GapSummary& s, const std::string& effect) {
  for (const analysis::RankedEffect& r : s.ranking)
    if (r.effect == effect) return r;
  ADD_FAILURE() << effect << " not ranked";
  return {};
}

TEST(GapBasin, CoupledInertiaIsScoredInItsBasinOfBestEvidence) {
  const BlindCase c = Load("case-050");
  ASSERT_EQ(c.unit.size(), 781u);
  // The current's noise dominates on most lines of this case: they take the admittance form.
  const std::size_t current =
      c.unit.admittance ? c.unit.size()
                        : static_cast<std::size_t>(std::count(c.unit.admittance_line.begin(),
                                                              c.unit.admittance_line.end(), true));
  EXPECT_GT(current, c.unit.size() / 2);
  const analysis::EffectFitter fitter(c.nominal, {c.unit});
  const analysis::EffectFit fit =
      fitter.FitKinds({analysis::EffectKind::kCoupledInertia}, {}, {}, 200);
  ASSERT_EQ(fit.effects.size(), 1u);
  ASSERT_EQ(fit.lowest_cost.size(), 1u) << "the lowest-cost basin was the answer";

  // The lowest-cost basin, refitted from where it ended, is where it was: lower cost, worse
  // evidence.
  const analysis::EffectFit low = fitter.Fit(fit.lowest_cost, {}, 200);
  EXPECT_LT(low.cost, fit.cost);
  EXPECT_LT(fit.cost + fit.occam, low.cost + low.occam - 1.0);

  // Its bounded parameters are charged for the share of their prior the data exclude, also
  // where one sits at a bound (f2 above the band: a coupling rigid over it), where Laplace
  // sees no curvature: the mass ratio the first mode's shift pins costs its ln(range /
  // width)^2 whatever the rest does.
  EXPECT_TRUE(std::isfinite(fit.occam));
  EXPECT_GT(fit.occam, 5.0);

  analysis::GapOptions o;
  o.heldout = false;
  o.calibrate = false;  // the exact simulation's basins (kept fixed: see the top)
  const analysis::GapSummary s = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.effect, "coupled_inertia") << s.message;
  EXPECT_LT(Ranked(s, "coupled_inertia").score, Ranked(s, "fixture_compliance").score);
  // 10 apart in evidence: no rival named.
  EXPECT_EQ(s.rival, "") << s.message;
}

// When two effects explain the data about equally (case-056: the spring fits 0.3 worse than
// the truth), the report says so: the winner, and the rival within 4.6 in evidence (at even
// prior odds; with the coupled inertia's default odds it wins by more than 4.6 here).
TEST(GapBasin, AnEqualRivalIsNamed) {
  const BlindCase c = Load("case-056");
  analysis::GapOptions o;
  o.heldout = false;
  o.calibrate = false;  // the exact simulation's basins (kept fixed: see the top)
  o.prior_odds.clear();
  const analysis::GapSummary s = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_TRUE(s.effect == "coupled_inertia" || s.effect == "fixture_compliance") << s.message;
  const std::string other =
      s.effect == "coupled_inertia" ? "fixture_compliance" : "coupled_inertia";
  EXPECT_EQ(s.rival, other) << s.message;
  EXPECT_GE(s.rival_score_gap, 0.0);
  EXPECT_LT(s.rival_score_gap, o.rival_margin);
  EXPECT_NE(s.message.find("hardly tell it from " + other), std::string::npos) << s.message;
  // A margin of 0 names no rival; a negative one is refused.
  o.rival_margin = 0.0;
  EXPECT_EQ(analysis::DiagnoseGap(c.nominal, {c.unit}, o).rival, "");
  o.rival_margin = -1.0;
  const analysis::GapSummary bad = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  EXPECT_FALSE(bad.usable);
  EXPECT_NE(bad.message.find("rival_margin"), std::string::npos) << bad.message;
}

// The prior odds (GapOptions::prior_odds) enter the evidence as -2 ln odds and decide between
// effects by exactly that much (seed 7's case-011: a second inertia at the rotor, mass ratio
// 0.144, f2 2.33 f0, S 35.5; the best spring fits it 7.3 worse than the truth). The coupled
// inertia wins on evidence, with its default odds and also at even odds; odds for the
// fixture spring just above exp(gap / 2) make the spring the answer and the inertia its
// rival, just below they do not. Odds that are not positive are refused.
TEST(GapBasin, PriorOddsWeighTheEvidenceByTwiceTheirLog) {
  const BlindCase c = Load("seed7-case-011");
  analysis::GapOptions o;
  o.heldout = false;
  o.calibrate = false;  // the exact simulation's basins (kept fixed: see the top)
  ASSERT_EQ(o.prior_odds.size(), 1u);
  ASSERT_EQ(o.prior_odds[0].first, analysis::EffectKind::kCoupledInertia);
  const double default_odds = o.prior_odds[0].second;
  const analysis::GapSummary with = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(with.usable) << with.message;
  EXPECT_EQ(with.effect, "coupled_inertia") << with.message;

  o.prior_odds.clear();
  const analysis::GapSummary even = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(even.usable) << even.message;
  EXPECT_EQ(even.effect, "coupled_inertia") << even.message;
  const double gap =
      Ranked(even, "fixture_compliance").score - Ranked(even, "coupled_inertia").score;
  ASSERT_GT(gap, 0.0);
  // With the default odds the inertia's score is 2 ln(odds) lower, the spring's unchanged.
  EXPECT_NEAR(Ranked(with, "coupled_inertia").score,
              Ranked(even, "coupled_inertia").score - 2.0 * std::log(default_odds), 1e-6);
  EXPECT_NEAR(Ranked(with, "fixture_compliance").score, Ranked(even, "fixture_compliance").score,
              1e-6);

  o.prior_odds = {{analysis::EffectKind::kFixtureCompliance, std::exp(gap / 2.0 + 0.5)}};
  const analysis::GapSummary spring = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(spring.usable) << spring.message;
  EXPECT_EQ(spring.effect, "fixture_compliance") << spring.message;
  EXPECT_EQ(spring.rival, "coupled_inertia") << spring.message;
  o.prior_odds = {{analysis::EffectKind::kFixtureCompliance, std::exp(gap / 2.0 - 0.5)}};
  const analysis::GapSummary still = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(still.usable) << still.message;
  EXPECT_EQ(still.effect, "coupled_inertia") << still.message;

  o.prior_odds = {{analysis::EffectKind::kCoupledInertia, 0.0}};
  const analysis::GapSummary bad = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  EXPECT_FALSE(bad.usable);
  EXPECT_NE(bad.message.find("prior_odds"), std::string::npos) << bad.message;
}

// A coupling rigid over the band (tests/data/gap-independent-coupled, stiff-seed11-case-006:
// J2 on a spring at 11.5 f0, mass ratio 0.060 at the rotor): its basin has f2 at the top of
// its range and q2 without meaning. On Laplace alone such a corner had no curvature and could
// not compete, so narrow coupled modes fitted to a few noisy lines in the band were scored and
// lost to the fixture spring. With the bounded parameters integrated over their priors the
// rigid basin is the answer: a better evidence than the lowest-cost in-band mode's, the
// loading the first mode's shift gives (mu (1 - x)^2 near 0.060), and a penalty that charges
// for pinning it. The data barely tell it from a fixture spring (the truth fits 0.1 better):
// the report names the other as the rival. The basins are compared on the impedance form,
// which this case took before the form was chosen per line (its relative sigma grows as
// |Z|^0.46); per line (the voltage's noise below 835 Hz, the current's above) a heavy J2 at a
// support node with a weak mode at 1.5 kHz fits 3 better than the rigid basin and wins, a basin
// the data barely tell apart; the diagnosis is the same either way (below).
TEST(GapBasin, ARigidCouplingCompetesAtItsBound) {
  const BlindCase c = Load("stiff-seed11-case-006", kCoupled, analysis::ResidualForm::kImpedance);
  const analysis::EffectFitter fitter(c.nominal, {c.unit});
  const analysis::EffectFit fit =
      fitter.FitKinds({analysis::EffectKind::kCoupledInertia}, {}, {}, 200);
  ASSERT_EQ(fit.effects.size(), 1u);
  const std::vector<double>& p = fit.effects[0].params;  // mass_ratio, f2_hz, q2, node share
  EXPECT_GT(p[1], 4.0 * fitter.f_hi_hz()) << "f2 " << p[1];
  EXPECT_NEAR(p[0] * (1.0 - p[3]) * (1.0 - p[3]), 0.060, 0.012);
  ASSERT_EQ(fit.lowest_cost.size(), 1u) << "the lowest-cost basin was the answer";
  const analysis::EffectFit low = fitter.Fit(fit.lowest_cost, {}, 200);
  EXPECT_LT(low.effects[0].params[1], fitter.f_hi_hz());  // a mode in the band
  EXPECT_LT(low.cost, fit.cost);
  EXPECT_LT(fit.cost + fit.occam, low.cost + low.occam);
  EXPECT_GT(fit.occam, 5.0);

  for (const analysis::ResidualForm form :
       {analysis::ResidualForm::kImpedance, analysis::ResidualForm::kAuto}) {
    const analysis::GapSummary s = Diagnose(c, form);
    ASSERT_TRUE(s.usable) << s.message;
    ASSERT_TRUE(s.effect == "coupled_inertia" || s.effect == "fixture_compliance") << s.message;
    EXPECT_EQ(s.rival, s.effect == "coupled_inertia" ? "fixture_compliance" : "coupled_inertia")
        << s.message;
  }
}

// An eddy branch whose corner (62 Hz) sits at the band's low edge under noise about the size
// of the signal per period (tests/data/gap-independent-eddy, seed 51's case-063, S 20.1). On
// the impedance form (every line) the data want the inductance drop without its transition:
// the lossy inductance's corner, a bounded parameter on [0.1 f_lo, 100 f_hi], sits at its lower
// bound (5 Hz) and is named far ahead of everything else. (With R2 fitted on six decades and
// the corner checked afterwards, the fit ran to R2 = 0, was rejected, and a channel delay was
// named.) With the form chosen per line (the current's noise above 830 Hz, where Z = U/I is
// biased low) the corner comes out near the truth's (45 Hz) and the fractional inductance, the
// other inductance-loss family, fits as well and is named by 3 in evidence.
TEST(GapBasin, AnEddyCornerBelowTheBandSitsAtItsBound) {
  const auto fitted = [](const analysis::RankedEffect& r, const std::string& name) {
    for (const auto& p : r.params)
      if (p.name == name) return p.value;
    ADD_FAILURE() << name << " not in " << r.effect;
    return 0.0;
  };
  for (const analysis::ResidualForm form :
       {analysis::ResidualForm::kImpedance, analysis::ResidualForm::kAuto}) {
    const BlindCase c = Load("seed51-case-063", kEddy, form);
    const analysis::GapSummary s = Diagnose(c, form);
    ASSERT_TRUE(s.usable) << s.message;
    const analysis::RankedEffect lossy = Ranked(s, "lossy_inductance");
    EXPECT_TRUE(lossy.plausible) << lossy.rejected;
    EXPECT_LT(lossy.score, Ranked(s, "channel_delay").score - 100.0);
    EXPECT_NEAR(fitted(lossy, "l2_h"), 98e-6, 60e-6);  // the truth's 98 uH
    if (form == analysis::ResidualForm::kImpedance) {
      EXPECT_EQ(s.effect, "lossy_inductance") << s.message;
      EXPECT_NEAR(fitted(lossy, "corner_hz"), 5.0, 0.5);  // 0.1 f_lo
    } else {
      EXPECT_TRUE(s.effect == "lossy_inductance" || s.effect == "fractional_inductance")
          << s.message;
      EXPECT_NEAR(fitted(lossy, "corner_hz"), 62.0, 31.0);
    }
  }
}

// A delay of 9 ns on a winding of small R (tests/data/gap-independent-delay): it raises Re Z as
// w^2 tau L, as a skin effect does, and fits 11 better. A delay is a signed scale: on a prior
// uniform over +-125 us its Occam penalty was 25.5 against the skin effect's 10.4 (log-uniform)
// and the skin effect was named; on a log-uniform prior in |tau| the two one-parameter
// penalties are alike and the delay is named.
TEST(GapBasin, ASmallDelayIsChargedOnALogPriorLikeTheSkinEffect) {
  const BlindCase c = Load("case-019", std::string(EOL_TEST_DATA_DIR) + "/gap-independent-delay/");
  const analysis::GapSummary s = Diagnose(c);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.effect, "channel_delay") << s.message;
  const analysis::RankedEffect delay = Ranked(s, "channel_delay");
  const analysis::RankedEffect skin = Ranked(s, "skin_effect");
  ASSERT_FALSE(delay.params.empty());
  EXPECT_NEAR(delay.params[0].value, 9.02e-9, 2e-9);
  EXPECT_LT(delay.cost, skin.cost - 5.0);
  const double delay_occam = delay.score - delay.cost, skin_occam = skin.score - skin.cost;
  EXPECT_LT(std::abs(delay_occam - skin_occam), 5.0) << delay_occam << " " << skin_occam;
}

// The truth: Z_L = L w_ref^(1 - n) (j w)^n, n = 0.5146, w_ref = 2 pi 316.2 Hz, no pure L left.
TEST(GapBasin, AWholeSemiInductanceSitsAtTheShareBoundOfOne) {
  const BlindCase c = Load("case-000", kSemi);
  ASSERT_EQ(c.unit.size(), 781u);
  const analysis::EffectFitter fitter(c.nominal, {c.unit});
  const analysis::EffectFit fit =
      fitter.FitKinds({analysis::EffectKind::kFractionalInductance}, {}, {}, 200);
  ASSERT_EQ(fit.effects.size(), 1u);
  const analysis::EffectSpec spec = fitter.Spec(analysis::EffectKind::kFractionalInductance);
  std::string why;
  EXPECT_TRUE(analysis::IsPlausible(spec, fit.effects[0], &why)) << why;
  const double share = fit.effects[0].params[0], order = fit.effects[0].params[1];
  const double match_hz = fit.effects[0].params[2];
  EXPECT_GT(share, 0.97);
  EXPECT_LE(share, 1.0);
  EXPECT_NEAR(order, 0.5146, 0.06);
  // |Z_L| of the fitted semi-inductance at the truth's reference: L w_ref (the truth's).
  const double l = c.nominal.motional.l_h, w_ref = 2.0 * std::numbers::pi * 316.23;
  const double w_m = 2.0 * std::numbers::pi * match_hz;
  const double fitted = share * l * std::pow(w_m, 1.0 - order) * std::pow(w_ref, order);
  EXPECT_NEAR(fitted / (l * w_ref), 1.0, 0.1);

  analysis::GapOptions o;
  o.heldout = false;
  o.calibrate = false;  // the exact simulation's basins (kept fixed: see the top)
  const analysis::GapSummary s = analysis::DiagnoseGap(c.nominal, {c.unit}, o);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.effect, "fractional_inductance") << s.message;
}

}  // namespace
}  // namespace eol
