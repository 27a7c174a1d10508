// The station end to end with the clamp's pressure varying from part to part (sim_bench.h:
// "clamp_pressure_spread_bar", the fixture spring k ~ p^(1/3)): the records carry the pressure
// read at clamp confirmation, teaching from them (TeachFromStore, as POST /api/teach does)
// finds f0 following it and proposes a recipe with resonance_f_ref_pressure_hz
// (analysis/qc/f0_pressure.h), which validates. With the pressure held (the default) the
// same teaching says why it is not used and the proposal has neither block nor limit.
#include <gtest/gtest.h>

#include <cstdio>
#include <iostream>
#include <mutex>
#include <nlohmann/json.hpp>

#include "../support/child_process.h"
#include "db/store.h"
#include "station/daemon/qc_service.h"
#include "station/daemon/recipe.h"
#include "station/daemon/station.h"

namespace eol::station {
namespace {

nlohmann::json TeachFromLine(const eol::testing::TempDir& dir, const std::string& name,
                             double spread_bar) {
  const nlohmann::json j = {{"station_id", name},
                            {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
                            {"db", dir / (name + ".sqlite")},
                            {"fixture", {{"driver", "sim"}}},
                            {"daq", {{"driver", "sim"}}},
                            {"sim",
                             {{"clamp_close_s", 0.02},
                              {"clamp_open_s", 0.02},
                              {"clamp_pressure_spread_bar", spread_bar}}}};
  Station s(ParseStationConfig(j, "test", ""));
  std::vector<std::string> golden;
  std::vector<double> pressures;
  for (int i = 0; i < 48; ++i) {
    char serial[16];
    std::snprintf(serial, sizeof serial, "P-%03d", i);
    const db::TestRecord r = s.RunTest(serial);
    if (r.outcome != analysis::Outcome::kPass) continue;
    golden.push_back(serial);
    pressures.push_back(r.conditions.clamp_pressure_bar.value());
  }
  EXPECT_GE(golden.size(), 31u);
  double lo = 1e9, hi = 0.0;
  for (double p : pressures) lo = std::min(lo, p), hi = std::max(hi, p);
  std::cout << name << ": " << golden.size() << " PASS units, clamp pressure " << lo << " - " << hi
            << " bar\n";
  std::mutex mu;
  analysis::TeachOptions o;
  o.mask_segments = 0;
  const TeachResult t = TeachFromStore(s.store(), mu, *s.recipe(), golden, o);
  EXPECT_EQ(t.kind, TeachResult::Kind::kProposed) << t.message << " " << t.report.dump();
  return t.report;
}

TEST(ClampPressureTeach, StationRecordsTeachThePressureNormalisedResonance) {
  eol::testing::TempDir dir;
  const nlohmann::json spread = TeachFromLine(dir, "spread", 0.5);
  const nlohmann::json& fit = spread.at("f0_pressure");
  std::cout << "spread 0.5 bar: " << fit.at("note").get<std::string>() << "\n";
  EXPECT_TRUE(fit.at("used").get<bool>());
  EXPECT_GT(fit.at("slope").get<double>(), 0.0);
  EXPECT_LT(fit.at("spread_after_pct").get<double>(), fit.at("spread_before_pct").get<double>());
  ASSERT_TRUE(spread.contains("recipe"));
  const Recipe proposed = ParseRecipe(spread.at("recipe"), "proposal");
  ASSERT_TRUE(proposed.f0_pressure.has_value());
  EXPECT_EQ(proposed.f0_pressure->exponent, fit.at("definition").at("exponent").get<double>());
  bool declared = false;
  for (const analysis::MeasurementSpec& l : proposed.limits)
    declared = declared || (l.name == "resonance_f_ref_pressure_hz" && l.limit.lo.has_value());
  EXPECT_TRUE(declared);

  const nlohmann::json held = TeachFromLine(dir, "held", 0.0);
  std::cout << "held: " << held.at("f0_pressure").at("note").get<std::string>() << "\n";
  EXPECT_FALSE(held.at("f0_pressure").at("used").get<bool>());
  const Recipe plain = ParseRecipe(held.at("recipe"), "proposal");
  EXPECT_FALSE(plain.f0_pressure.has_value());
  for (const analysis::MeasurementSpec& l : plain.limits)
    EXPECT_NE(l.name, "resonance_f_ref_pressure_hz");
}

}  // namespace
}  // namespace eol::station
