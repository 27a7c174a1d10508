// Test conditions (station/daemon/conditions.h) through the real sequencer on the simulated bench
// with a real SQLite file: recorded on every test, and a condition out of the recipe's window
// ends the test as ERROR "condition out of window: ..." (never PASS, never FAIL), unless the
// recipe's policy is "record".
#include <gtest/gtest.h>

#include <cmath>

#include "../support/child_process.h"
#include "analysis/qc/measurement_names.h"
#include "drivers/io/json_config.h"
#include "drivers/sim/sim_daq.h"
#include "drivers/sim/sim_fixture.h"
#include "station/daemon/sequencer.h"

namespace eol::station {
namespace {

using analysis::Outcome;

nlohmann::json BaseRecipe() {
  return io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
}

// Within 0..45 degC the simulated population (R 0.5 ohm +-2 %) reads 20 +-5 degC.
nlohmann::json Conditions(const std::string& policy = "error") {
  return {{"winding_temperature_c", {{"r_ref_ohm", 0.5}, {"t_ref_c", 20}, {"lo", 0}, {"hi", 45}}},
          {"excitation_v_rms", {{"lo", 1.0}, {"hi", 1.6}}},
          {"excitation_a_rms", {{"lo", 0.01}, {"hi", 5.0}}},
          {"out_of_window", policy}};
}

class ConditionsTest : public ::testing::Test {
 protected:
  void Build(const nlohmann::json& conditions) {
    drivers::SimBenchSettings bench_settings;
    bench_settings.clamp_close_s = 0.05;
    bench_settings.clamp_open_s = 0.03;
    bench_ = std::make_shared<drivers::SimBench>(bench_settings);
    fixture_ = std::make_unique<drivers::SimFixture>(bench_);
    daq_ = std::make_unique<drivers::SimDaq>(bench_, drivers::SimDaqSettings{});
    ASSERT_TRUE(fixture_->Connect().ok());
    ASSERT_TRUE(daq_->Connect().ok());
    store_ = db::Store::Open(dir_ / "eol.sqlite");
    nlohmann::json j = BaseRecipe();
    j["conditions"] = conditions;
    recipe_ = std::make_shared<const Recipe>(ParseRecipe(j, "test"));
    board_ = std::make_unique<StatusBoard>("test");
    sequencer_ = std::make_unique<Sequencer>(*fixture_, *daq_, *store_, recipe_, *board_,
                                             SequencerOptions{});
  }

  // A good unit whose winding resistance reads as `winding_c` degC (0 = its drawn R).
  db::TestRecord Test(const std::string& serial, double winding_c = 0.0) {
    analysis::SimUnit u = analysis::DrawUnit(bench_->settings().population, serial, false);
    if (winding_c != 0.0) u.r_ohm = 0.5 * (1.0 + kCopperAlphaPerK * (winding_c - 20.0));
    bench_->LoadUnit(u);
    unit_ = u;
    return sequencer_->RunTest(serial);
  }

  static std::string Reasons(const db::TestRecord& r) {
    std::string all;
    for (const auto& s : r.reasons) all += s.text + " | ";
    return all;
  }

  eol::testing::TempDir dir_;
  std::shared_ptr<drivers::SimBench> bench_;
  std::unique_ptr<drivers::Fixture> fixture_;
  std::unique_ptr<drivers::Daq> daq_;
  std::unique_ptr<db::Store> store_;
  std::shared_ptr<const Recipe> recipe_;
  std::unique_ptr<StatusBoard> board_;
  std::unique_ptr<Sequencer> sequencer_;
  analysis::SimUnit unit_;
};

TEST_F(ConditionsTest, InWindowPassesAndRecordsEveryCondition) {
  Build(Conditions());
  const db::TestRecord r = Test("COND-1");
  ASSERT_EQ(r.outcome, Outcome::kPass) << Reasons(r);
  const auto stored = store_->Test(r.id, false);
  ASSERT_TRUE(stored);
  const db::TestConditions& c = stored->conditions;
  // Temperature from the fitted R against the simulator's true R (fit error << 1 K).
  const double truth_c = WindingTemperatureC(unit_.r_ohm, 0.5, 20.0);
  EXPECT_NEAR(c.winding_temperature_c.value(), truth_c, 1.0);
  // The level the motor saw: the multisine's rms is its peak over its crest factor.
  const double v_rms = c.excitation_v_rms.value();
  EXPECT_NEAR(v_rms, recipe_->excitation.peak_v / c.crest_factor.value(), 0.02 * v_rms);
  EXPECT_GT(c.excitation_a_rms.value(), 0.0);
  // Pressure read at confirmation and through the excitation, inside the recipe's window.
  for (const std::optional<double>& p :
       {c.clamp_pressure_bar, c.clamp_pressure_min_bar, c.clamp_pressure_max_bar}) {
    ASSERT_TRUE(p.has_value());
    EXPECT_GE(*p, recipe_->clamp_pressure_lo_bar);
    EXPECT_LE(*p, recipe_->clamp_pressure_hi_bar);
  }
  EXPECT_EQ(c.conditions_in_window, true);
}

TEST_F(ConditionsTest, HotWindingIsAnErrorNotAPassAndNotAFail) {
  Build(Conditions());
  // R = 0.582 ohm is inside the R limits (0.4..0.6): only the temperature says it is hot.
  const db::TestRecord r = Test("COND-HOT", 62.0);
  EXPECT_EQ(r.outcome, Outcome::kError) << Reasons(r);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().code, analysis::ReasonCode::kCondition);
  EXPECT_EQ(r.reasons.front().text.rfind("condition out of window: winding temperature 6", 0), 0u)
      << Reasons(r);
  EXPECT_NE(r.reasons.front().text.find("outside 0.0..45.0 degC"), std::string::npos) << Reasons(r);
  const auto stored = store_->Test(r.id, false);
  ASSERT_TRUE(stored);
  EXPECT_EQ(stored->outcome, Outcome::kError);
  EXPECT_EQ(stored->conditions.conditions_in_window, false);
  // The measurements are kept for the audit: R itself was inside its limits.
  for (const auto& m : stored->measurements)
    if (m.name == analysis::names::kWindingROhm) {
      EXPECT_EQ(m.outcome, analysis::MeasurementOutcome::kPass);
    }
}

TEST_F(ConditionsTest, ExcitationLevelOutOfWindowIsAnError) {
  nlohmann::json c = Conditions();
  c["excitation_v_rms"] = {{"lo", 1.5}, {"hi", 1.6}};  // the 2 V-peak multisine gives ~1.3 V rms
  Build(c);
  const db::TestRecord r = Test("COND-LEVEL");
  EXPECT_EQ(r.outcome, Outcome::kError) << Reasons(r);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().text.rfind("condition out of window: excitation level 1.", 0), 0u)
      << Reasons(r);
  EXPECT_NE(r.reasons.front().text.find("outside 1.500..1.600 V rms"), std::string::npos);
}

TEST_F(ConditionsTest, RecordPolicyKeepsTheVerdictAndRecordsTheExcursion) {
  Build(Conditions("record"));
  const db::TestRecord r = Test("COND-REC", 60.0);
  EXPECT_EQ(r.outcome, Outcome::kPass) << Reasons(r);
  const auto stored = store_->Test(r.id, false);
  EXPECT_EQ(stored->conditions.conditions_in_window, false);
  EXPECT_NEAR(stored->conditions.winding_temperature_c.value(), 60.0, 1.0);
}

TEST(ConditionsRecipe, InvalidSectionsNameThePathAndTheRule) {
  auto message = [](const nlohmann::json& conditions) {
    nlohmann::json j = BaseRecipe();
    j["conditions"] = conditions;
    try {
      ParseRecipe(j, "r.json");
    } catch (const io::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  nlohmann::json c = Conditions("normalise");
  EXPECT_NE(message(c).find("/conditions/out_of_window: must be \"error\" or \"record\""),
            std::string::npos)
      << message(c);
  EXPECT_NE(message(c).find("R is not normalised"), std::string::npos);
  c = Conditions();
  c["winding_temperature_c"]["hi"] = -5;
  EXPECT_NE(message(c).find("/conditions/winding_temperature_c/hi: must be greater than lo"),
            std::string::npos)
      << message(c);
  c = Conditions();
  c["winding_temperature_c"].erase("r_ref_ohm");
  EXPECT_NE(message(c).find("/conditions/winding_temperature_c/r_ref_ohm"), std::string::npos)
      << message(c);
  c = Conditions();
  c["humidity"] = 3;
  EXPECT_NE(message(c).find("humidity"), std::string::npos) << message(c);
}

TEST(ConditionsMath, TemperatureFromResistanceKnownAnswer) {
  // R = R_ref (1 + 0.00393 (T - T_ref)): 0.5 ohm at 20 degC reads 0.5393 ohm at 40 degC.
  EXPECT_NEAR(WindingTemperatureC(0.5393, 0.5, 20.0), 40.0, 1e-9);
  EXPECT_NEAR(WindingTemperatureC(0.5, 0.5, 20.0), 20.0, 1e-12);
  EXPECT_NEAR(RmsAfter({9, 9, 3, -3, 3, -3}, 2), 3.0, 1e-12);
  EXPECT_TRUE(std::isnan(RmsAfter({1.0}, 1)));
}

}  // namespace
}  // namespace eol::station
