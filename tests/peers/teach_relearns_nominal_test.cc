// `eol teach` relearns the excitation design's nominal motor from the golden units
// (station/daemon/qc_service.h RelearnNominal). Golden units of
// tests/peers/independent_population.py (the ten-pole motor written apart from analysis/, Q about
// 41 where the design says 50) taught on recipes/pmsm-10pole-fast.json: the taught limits put Q 50
// outside them, so keeping the design's nominal made the proposal refuse itself. Relearned, the
// nominal is the units' own, and the fast excitation is then short of its sigma_f0 requirement at
// that lower Q: teach writes the proposal saying so, nothing loads it (a unit analysed with it is
// refused, never judged), and `eol design-excitation` redesigns it into a recipe that passes good
// units.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

namespace eol::testing {
namespace {

using namespace std::chrono_literals;

CliRun Eol(std::vector<std::string> args, bool merge_stderr = true) {
  return RunEol(std::move(args), merge_stderr, 300s);
}

TEST(TeachRelearnsNominal, UnitsUnlikeTheDesignGiveAProposalToRedesignNeverALoadableOne) {
  TempDir dir;
  ChildProcess gen({"/usr/bin/python3",
                    std::string(EOL_SOURCE_DIR) + "/tests/peers/independent_population.py", "--out",
                    dir / "pop", "--seed", "11", "--good", "42", "--one-soft", "0", "--three-soft",
                    "0", "--all-soft", "0"});
  ASSERT_EQ(gen.Wait(120s).value_or(-1), 0) << gen.output();
  std::vector<std::string> args = {"teach",
                                   "--recipe",
                                   std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole-fast.json",
                                   "--out",
                                   dir / "taught.json",
                                   "--json",
                                   "--golden"};
  for (int i = 1; i <= 40; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "/unit-%04d.csv", i);
    args.push_back(dir / "pop" + name);
  }
  CliRun r = Eol(args, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json report = nlohmann::json::parse(r.out);
  const std::string short_of = report["excitation_short_of_design"];
  EXPECT_NE(short_of.find("cannot be loaded or approved yet"), std::string::npos) << short_of;
  EXPECT_NE(short_of.find("eol design-excitation"), std::string::npos) << short_of;

  std::ifstream in(dir / "taught.json");
  const nlohmann::json taught = nlohmann::json::parse(in);
  const nlohmann::json& nominal = taught["excitation_design"]["nominal"];
  EXPECT_LT(nominal["q"].get<double>(), 47.0) << nominal.dump();  // the units', not 50
  EXPECT_NEAR(nominal["f0_hz"].get<double>(), 390.0, 10.0) << nominal.dump();
  EXPECT_NE(taught["description"].get<std::string>().find("Excitation-design nominal relearned"),
            std::string::npos);

  // Not loadable: a unit analysed with it is refused naming the requirement.
  const std::string good = dir / "pop/unit-0041.csv";
  r = Eol({"analyze", "--measured", good, "--recipe", dir / "taught.json"});
  EXPECT_NE(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("/excitation_design/sigma_f0_hz"), std::string::npos) << r.out;

  // Redesigned, it loads and passes the good units left out of teaching.
  r = Eol({"design-excitation", "--recipe", dir / "taught.json", "--out", dir / "next.json"});
  ASSERT_EQ(r.code, 0) << r.out;
  for (const std::string unit : {"unit-0041.csv", "unit-0042.csv"}) {
    r = Eol({"analyze", "--measured", dir / "pop/" + unit, "--recipe", dir / "next.json", "--json"},
            false);
    ASSERT_EQ(r.code, 0) << r.out;
    EXPECT_EQ(nlohmann::json::parse(r.out)["verdict"]["outcome"], "PASS") << unit << ": " << r.out;
  }
}

}  // namespace
}  // namespace eol::testing
