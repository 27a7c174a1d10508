// `eol production-bench` at reduced size through the built binary, fixed seed: limits taught
// from 50 golden units let no rotor with every magnet poorly cemented escape, reject at most
// 0.3 % of good units, and every unit is counted once per rule.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "../support/child_process.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

nlohmann::json Bench(const std::vector<std::string>& extra, int* code) {
  std::vector<std::string> args = {EOL_BINARY, "production-bench", "--json"};
  args.insert(args.end(), extra.begin(), extra.end());
  ChildProcess p(args, /*merge_stderr=*/false);
  *code = p.Wait(900s).value_or(-1);
  if (*code != 0) return {{"output", p.output()}};
  return nlohmann::json::parse(p.output());
}

TEST(ProductionBenchCli, TaughtLimitsMeetTheTargetsAtReducedSize) {
  int code = -1;
  const nlohmann::json j = Bench({"--units", "2000", "--seed", "7"}, &code);
  ASSERT_EQ(code, 0) << j.dump();
  ASSERT_TRUE(j["usable"].get<bool>()) << j.dump();
  EXPECT_EQ(j["units"], 2000);
  int total = 0, good = 0, all_soft = 0;
  for (const auto& c : j["classes"]) {
    const int units = c["units"];
    total += units;
    for (const char* rule : {"taught", "recipe", "naive"}) {
      const auto& r = c["rules"][rule];
      EXPECT_EQ(r["pass"].get<int>() + r["fail"].get<int>() + r["error"].get<int>(), units)
          << c.dump();
    }
    if (c["class"] == "good") good = units;
    if (c["class"] == "all_soft") {
      all_soft = units;
      EXPECT_EQ(c["rules"]["taught"]["pass"], 0) << "a rotor with every magnet poorly cemented "
                                                    "escaped: "
                                                 << c.dump();
    }
  }
  EXPECT_EQ(total, 2000);
  EXPECT_GT(good, 1600);    // 90 % good at the default rates
  EXPECT_GT(all_soft, 20);  // 2 % all_soft: the target is exercised
  EXPECT_LE(j["rates"]["taught"]["false_reject_rate"].get<double>(), 0.003) << j.dump();
  EXPECT_EQ(j["teach"]["units_used"].get<int>() <= 50, true);
}

TEST(ProductionBenchCli, BadOptionsAreNamed) {
  int code = -1;
  const nlohmann::json j = Bench({"--units", "0"}, &code);
  EXPECT_EQ(code, 1);
  EXPECT_NE(j["output"].get<std::string>().find("units must be in"), std::string::npos) << j.dump();
}

}  // namespace
}  // namespace eol
