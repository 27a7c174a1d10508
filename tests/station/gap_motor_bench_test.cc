// `eol gap --quantity mobility` on the real motor bench (shared/data/motor-bench-multisine:
// a servo motor driving a load inertia through a flexible coupling). The simulation is a
// rigid shaft, M = g / (s + a), the motor and load as one inertia on a viscous damper, with
// g = Kt / J_total = 100 rad/s^2/A and a = 13.8 1/s (what the 11-30 Hz lines give, where the
// coupling is stiff: the designer's rigid-body numbers). The measured current-to-angle
// transfer H = j w Theta_motor / I_q comes straight from the raw recording (periodic average,
// first period dropped). The gap is the coupling's mode: anti-resonance 53 Hz, resonance
// 77 Hz. The loop's sampling delay also shows (about 0.1 ms), so the diagnosis is the pair
// second_mode + channel_delay.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/support/child_process.h"

namespace eol {
namespace {

using testing::ChildProcess;
using testing::TempDir;

const std::string kDir = std::string(EOL_TEST_DATA_DIR) + "/motor-bench-multisine/";

nlohmann::json Diagnose(const std::string& recording, const TempDir& dir, std::string* text) {
  std::ofstream(dir / "rigid.json")
      << R"({"model": "rigid_shaft", "gain_rad_per_s2_per_a": 100.0, "damping_per_s": 13.8})";
  ChildProcess p({EOL_BINARY, "gap", "--quantity", "mobility", "--sim", dir / "rigid.json",
                  "--measured", kDir + recording, "--json-out", dir / "out.json", "--plot",
                  dir / "bench.svg"});
  const auto code = p.Wait(std::chrono::seconds(120));
  *text = p.output();
  EXPECT_EQ(code, 0) << p.output();
  std::ifstream in(dir / "out.json");
  return nlohmann::json::parse(in);
}

void ExpectCouplingMode(const nlohmann::json& j, const std::string& text, double shrink) {
  const std::string effect = j["effect"];
  EXPECT_NE(effect.find("second_mode"), std::string::npos) << text;
  const double f = j["params"]["f_hz"].get<double>();
  EXPECT_NEAR(f, 77.0, 3.0) << text;
  // The rigid shaft misses the coupling by far; the mode (and the delay) take most of it.
  EXPECT_GT(j["gap_before"].get<double>(), 50.0);
  EXPECT_LT(j["gap_after"].get<double>(), j["gap_before"].get<double>() / shrink);
  EXPECT_LT(j["heldout"]["gap_after"].get<double>(),
            j["heldout"]["gap_before"].get<double>() / shrink);
  // The most significant band holds the anti-resonance or the resonance.
  ASSERT_FALSE(j["where"].empty());
  const double lo = j["where"][0]["f_lo_hz"], hi = j["where"][0]["f_hi_hz"];
  EXPECT_TRUE((lo <= 77.0 && hi >= 77.0) || (lo <= 53.0 && hi >= 53.0)) << lo << "-" << hi;
}

TEST(GapMotorBench, FullMultisineNamesTheCouplingMode) {
  TempDir dir;
  std::string text;
  const nlohmann::json j = Diagnose("typeA.csv.gz", dir, &text);
  ExpectCouplingMode(j, text, 5.0);
  EXPECT_EQ(j["quantity"], "mobility");
  EXPECT_EQ(j["measurements"][0]["kind"], "recording");
  EXPECT_EQ(j["measurements"][0]["lines"], 240);
  EXPECT_EQ(j["heldout"]["method"], "interleaved-2fold");
}

TEST(GapMotorBench, RandomOddMultisineToo) {
  TempDir dir;
  std::string text;
  // 60 excited lines only, and the residual is model error (friction, the drive's
  // nonlinearity), not noise: the held-out shrink is a little smaller.
  const nlohmann::json j = Diagnose("typeB.csv.gz", dir, &text);
  ExpectCouplingMode(j, text, 4.0);
  EXPECT_EQ(j["measurements"][0]["lines"], 60);
}

}  // namespace
}  // namespace eol
