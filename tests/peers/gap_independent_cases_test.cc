// `eol gap` on blind cases from an independent generator (tests/peers/independent_gap_cases.py:
// the clamped motor's physics written in numpy, no code shared with analysis/): random motors,
// one hidden effect or none, an 8-period multisine with noise on both channels. Fixed seed,
// 20 cases (10 coupled second inertias, 5 without an effect, 5 fixture springs), run with the
// sigma's degrees of freedom given (--sigma-periods 8).
// Contract (issue 13): a case without an effect is always `none`; the coupled second inertia is
// named in at least 8 of 10 of the cases the data can tell from a fixture spring (the script's
// "separable": the true model's cost, -2 ln L as `eol gap` scores it in the report's residual
// form, at least 10 below the best fixture spring's; on this seed 4 of the 10; of the others
// four more are named with the prior odds of 15, and in the two named `fixture_compliance` the
// spring fits better than the truth): at least 8 of the 10 in all; at least 90 % of the
// separable cases are named (14 of 14).
#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/child_process.h"

namespace eol::testing {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

std::string Script() {
  return std::string(EOL_SOURCE_DIR) + "/tests/peers/independent_gap_cases.py";
}

TEST(GapIndependentCases, NamesCoupledInertiaAndNeverInventsAnEffect) {
  std::string tmpl = (std::filesystem::temp_directory_path() / "eol_gap_cases_XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  const std::string dir = tmpl;

  ChildProcess gen({kPython, Script(), "--out", dir, "--cases", "20", "--seed", "7", "--plan",
                    "coupled_inertia,none,coupled_inertia,fixture_spring"});
  ASSERT_EQ(gen.Wait(std::chrono::seconds(120)).value_or(-1), 0) << gen.output();
  // The exact simulation: the nominal kept at the simulation's values (issue 38's calibration
  // takes the weak second inertias into J's tolerance; the tolerance cases below test it).
  ChildProcess score({kPython, Script(), "--out", dir, "--score", "--eol", EOL_BINARY, "--",
                      "--sigma-periods", "8", "--fixed-nominal"});
  ASSERT_EQ(score.Wait(std::chrono::seconds(600)).value_or(-1), 0) << score.output();
  std::ifstream in(dir + "/score.json");
  ASSERT_TRUE(in) << dir << "/score.json: " << score.output();
  const nlohmann::json s = nlohmann::json::parse(in);

  int coupled = 0, coupled_separable = 0, coupled_named = 0, coupled_named_all = 0;
  for (const auto& row : s["rows"]) {
    const std::string hidden = row["hidden"];
    if (hidden == "none") {
      EXPECT_EQ(row["answer"], "none") << row["case"];
    }
    if (hidden.rfind("coupled_inertia", 0) == 0) {
      ++coupled;
      coupled_named_all += row["ok"].get<bool>() ? 1 : 0;
      if (!row["separable"].get<bool>()) continue;
      ++coupled_separable;
      coupled_named += row["ok"].get<bool>() ? 1 : 0;
    }
  }
  EXPECT_EQ(coupled, 10);
  EXPECT_GE(coupled_separable, 4) << score.output();
  EXPECT_GE(coupled_named, 0.8 * coupled_separable) << score.output();
  // Issue 13's 8 of 10 over every coupled case, near ties included (this seed: 8).
  EXPECT_GE(coupled_named_all, 8) << score.output();
  const double named = s["separable_named"], separable = s["separable"];
  EXPECT_GE(named, 0.9 * separable) << score.output();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

// Issue 38: the simulation is not the unit. tests/peers/independent_tolerance_cases.py (written
// apart from analysis/, the physics of independent_gap_cases.py) puts every design parameter of
// the unit off its simulation by its tolerance (R, L, torque constant, J, k by 5-12 %, damping
// x0.5-2, a DAQ gain error of 0.2-1.5 %), motors 250 Hz - 2 kHz, and none, one or two hidden
// effects; its oracle marks a case separable when the truth beats the tolerance-calibrated
// nominal without each effect by the decision rule's margin. Nine cases (seed 2: three of each
// class), the six of no effect and of one scored, keep the run short (pairs are below their
// target and asserted nowhere yet); `eol gap-bench --independent DIR` runs the 48-case
// figures (analysis/gap/README.md). Contract: a calibration-only case is always `none`, never a
// pair; every separable single effect is named alone.
TEST(GapIndependentCases, ACalibrationIsNoneAndASingleEffectIsNamedAlone) {
  std::string tmpl = (std::filesystem::temp_directory_path() / "eol_gap_tol_XXXXXX").string();
  ASSERT_NE(mkdtemp(tmpl.data()), nullptr);
  const std::string dir = tmpl;
  const std::string script =
      std::string(EOL_SOURCE_DIR) + "/tests/peers/independent_tolerance_cases.py";
  ChildProcess gen({kPython, script, "--out", dir, "--cases", "9", "--seed", "2"});
  ASSERT_EQ(gen.Wait(std::chrono::seconds(300)).value_or(-1), 0) << gen.output();
  ChildProcess score({kPython, script, "--out", dir, "--score", "--eol", EOL_BINARY, "--classes",
                      "none,single", "--", "--sigma-periods", "8"});
  ASSERT_EQ(score.Wait(std::chrono::seconds(1200)).value_or(-1), 0) << score.output();
  std::ifstream in(dir + "/score.json");
  ASSERT_TRUE(in) << dir << "/score.json: " << score.output();
  const nlohmann::json s = nlohmann::json::parse(in)["summary"];
  EXPECT_EQ(s["none"]["cases"], 3);
  EXPECT_EQ(s["none"]["ok"], 3) << score.output();
  EXPECT_EQ(s["none"]["pair_answered"], 0) << score.output();
  EXPECT_GE(s["single"]["separable"], 2) << score.output();
  EXPECT_EQ(s["single"]["separable_ok"], s["single"]["separable"]) << score.output();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
}

}  // namespace
}  // namespace eol::testing
