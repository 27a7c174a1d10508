// `eol gap` on a real, public, measured loudspeaker impedance (tests/data/
// loudspeaker-ls10-impedance: a Dayton LS10-44 woofer on a baffle, 9999 lines 1-5000 Hz, GPL-3.0,
// source in its README). The simulation is the lumped Thiele-Small model of the same unit,
// Z = Re + j w Le + Bl^2 / (Rms + j w Mms + 1 / (j w Cms)), with the parameters the classical
// added-mass method gives (tests/peers/lumped_transducer_sim.py sim; committed as sim.csv.gz).
// The real voice coil is not a pure inductance: eddy currents make it semi-inductive
// (|Z| ~ w^0.6-0.7 above 1 kHz, phase about 60 deg), and the cone adds a broad resonance near
// 370 Hz. The file has no sigma: eol estimates it from the line-to-line scatter.
//
// The reference for "the right physics" is the independent SciPy refit
// (lumped_transducer_sim.py refit --form impedance, the residual form eol takes for an estimated
// sigma): the nominal's own parameters plus a fractional inductance R + s L + K (j w)^n +
// motional reach g = 7.69; with the broad mode as well, 3.959 (eol's split reaches 3.959).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "tests/support/child_process.h"

namespace eol {
namespace {

using testing::ChildProcess;
using testing::TempDir;

const std::string kDir = std::string(EOL_TEST_DATA_DIR) + "/loudspeaker-ls10-impedance/";
constexpr double kRightPhysicsRefitG = 7.69;  // nominal + K (j w)^n refitted (SciPy, above)

nlohmann::json Diagnose(const TempDir& dir, const std::vector<std::string>& extra,
                        std::string* text) {
  std::vector<std::string> argv = {EOL_BINARY,          "gap",           "--sim",
                                   kDir + "sim.csv.gz", "--measured",    kDir + "free.csv.gz",
                                   "--json-out",        dir / "out.json"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  ChildProcess p(argv);
  const auto code = p.Wait(std::chrono::seconds(600));
  *text = p.output();
  EXPECT_EQ(code, 0) << p.output();
  std::ifstream in(dir / "out.json");
  return nlohmann::json::parse(in);
}

TEST(GapPublicImpedance, LoudspeakerNamesTheLossyCoilAndSplitsCalibrationFromStructure) {
  TempDir dir;
  std::string text;
  // The nominal stays at the simulation's values (--fixed-nominal): calibrating it within the
  // design's tolerances on all 9999 lines costs more than 7 CPU-minutes, too long for the
  // suite; the calibrated run on this curve is not yet measured (analysis/gap/README.md).
  const nlohmann::json j = Diagnose(dir, {"--fixed-nominal"}, &text);
  ASSERT_EQ(j["measurements"].size(), 1u) << text;
  EXPECT_EQ(j["measurements"][0]["lines"], 9999);
  EXPECT_TRUE(j["measurements"][0]["sigma_estimated"].get<bool>());

  // The effect names the voice coil's inductance loss (alone or with a partner).
  const std::string effect = j["effect"];
  EXPECT_TRUE(effect.find("fractional_inductance") != std::string::npos ||
              effect.find("lossy_inductance") != std::string::npos)
      << text;
  if (j["params"].contains("order")) {
    const double n = j["params"]["order"];
    EXPECT_GT(n, 0.5) << text;
    EXPECT_LT(n, 0.8) << text;
  }

  // The lumped model misses by far; the diagnosis takes most of it, also on held-out lines,
  // and lands within a small factor of the right-physics refit.
  const double before = j["gap_before"], after = j["gap_after"];
  // The reference's form: an estimated sigma does not follow a line's own noise draw, so the
  // impedance form is kept although the relative sigma grows with |Z| (noise.h).
  EXPECT_EQ(j["residual_form"], "impedance") << text;
  EXPECT_GT(before, 50.0) << text;
  EXPECT_LT(after, before / 15.0) << text;
  EXPECT_LT(after, 1.5 * kRightPhysicsRefitG) << text;
  EXPECT_LT(j["heldout"]["gap_after"].get<double>(),
            j["heldout"]["gap_before"].get<double>() / 15.0)
      << text;

  // Calibration and structure apart: the shares of the excess add up to one, the nominal's
  // own parameters take a part and the structural effect the rest, which a refit alone leaves.
  const nlohmann::json& s = j["split"];
  const double cal = s["share_calibration"], str = s["share_structure"], left = s["share_left"];
  EXPECT_NEAR(cal + str + left, 1.0, 1e-6) << s.dump();
  EXPECT_GT(cal, 0.5) << s.dump();
  EXPECT_GT(str, 0.05) << s.dump();
  EXPECT_LT(left, 0.05) << s.dump();
  const double g_nominal = s["g_nominal"], g_refit = s["g_refit"];
  const double g_refit_effect = s["g_refit_effect"];
  EXPECT_LT(g_refit, g_nominal) << s.dump();
  EXPECT_LT(g_refit_effect, g_refit / 5.0) << s.dump();
  EXPECT_LT(g_refit_effect, kRightPhysicsRefitG) << s.dump();
  EXPECT_LT(s["heldout_g_refit_effect"].get<double>(), 1.2 * g_refit_effect) << s.dump();

  // A loudspeaker's simulation names no rotor: the J_r used is the recipe's, and said so.
  EXPECT_EQ(j["calibration"]["inertia_source"], "recipe") << j["calibration"].dump();
  EXPECT_NE(text.find("assumed from the recipe's rotor"), std::string::npos) << text;
}

}  // namespace
}  // namespace eol
