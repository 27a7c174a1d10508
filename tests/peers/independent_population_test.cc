// Taught limits on populations simulated independently of analysis/ (issue 12), through
// tests/peers/population_rejects.py (analysis/qc/README.md's workflow: `eol teach` from 40 golden
// units of tests/peers/independent_population.py, then `eol analyze --recipe taught` unit by unit).
//
// 1. Poorly cemented rotors (fixed seeds 101 and 202): soft bonds lose 94-99 % of their
//    stiffness (0.96 is the paper's magnets-cemented-on-one-side case; the blind populations'
//    all-ten escapes sat 17-30 Hz low, i.e. losses of about 0.955-0.97). Holds: at least 19 of
//    the 20 all-ten-soft rotors rejected; good units rejected at most 0.3 % (of 2 x 150, so
//    none; the expected false-reject rate teach reports states it finely, and is held too);
//    the three-soft rejection is printed (the goal is half).
// 2. POD (MIL-HDBK-1823A hit/miss, fitted by `eol pod`) over the transition (seed 303): 200
//    all-ten-soft rotors with losses uniform on 0.88-0.99 and 100 one-soft rotors. Holds: the
//    all-magnets a90/95 (likelihood ratio) exists and is at most 0.95: every all-ten softness
//    at least as severe as the paper's one-side case is found with 90 % POD at 95 %
//    confidence. The one-magnet POD is printed: this fixture does not reach 90 % for one soft
//    magnet at any loss below about 0.98.
// 3. The same sweep taught by physics (the default) and by the even split: physics rejects at
//    least as many all-ten-soft and more one-soft rotors. (Not a90: physics also catches a
//    few rotors at losses of 0.85-0.9, which flattens the fitted logistic; on population seed
//    1 its a90 comes out 0.001 above the even split's although it rejects more in every
//    loss bin.) Parts 1 and 2 also hold with `--allocation even` on this generator (its good
//    units spread less than the blind populations', so both f0 limits sit close): part 3 is
//    the one that tells the allocations apart.
// 4. The resonance's residue T^2/J (motional_residue_ohm_per_s) earns its place: on rotors
//    with all ten bonds at losses of 0.85-0.94 (f0 1-4 % low, mostly inside the good spread)
//    the shipped recipe taught with it rejects clearly more than the same recipe without it.
// 5. The resonance at the reference clamp pressure (analysis/qc/f0_pressure.h) is taught when
//    every unit's clamp pressure goes with it (population_rejects.py --clamp-pressure), and then
//    never rejects fewer all-ten-soft rotors nor more good ones than the same teaching without
//    the pressure.
// Milder softness (losses below about 0.9) moves f0 by less than the good units' spread: no
// limit on this fixture sees it (analysis/qc/README.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/support/child_process.h"

namespace eol::testing {
namespace {

class IndependentPopulation : public ::testing::Test {
 public:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("eol_indep_pop_" + std::to_string(getpid()) + "_" +
            std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  // Runs population_rejects.py with `args` and returns its JSON summary.
  nlohmann::json Rejects(const std::string& name, std::vector<std::string> args,
                         const std::string& recipe = std::string(EOL_SOURCE_DIR) +
                                                     "/recipes/pmsm-10pole.json") {
    const std::string json_path = (dir_ / (name + ".json")).string();
    std::vector<std::string> argv = {
        "/usr/bin/python3",
        std::string(EOL_SOURCE_DIR) + "/tests/peers/population_rejects.py",
        "--eol",
        EOL_BINARY,
        "--recipe",
        recipe,
        "--golden",
        "40",
        "--jobs",
        "2",
        "--workdir",
        (dir_ / name).string(),
        "--json",
        json_path};
    argv.insert(argv.end(), args.begin(), args.end());
    ChildProcess p(argv, true);
    const auto code = p.Wait(std::chrono::seconds(300));
    std::cout << p.output();
    EXPECT_EQ(code.value_or(-1), 0) << p.output();
    std::ifstream in(json_path);
    if (!in) return nlohmann::json();
    return nlohmann::json::parse(in);
  }

  const std::filesystem::path& dir() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

TEST_F(IndependentPopulation, TaughtLimitsCatchPoorlyCementedRotorsAndKeepGoodUnits) {
  const nlohmann::json j =
      Rejects("poor", {"--seeds", "101,202", "--good", "150", "--one-soft", "0", "--three-soft",
                       "10", "--all-soft", "10", "--loss-lo", "0.94", "--loss-hi", "0.99"});
  ASSERT_TRUE(j.is_object());
  const auto& t = j.at("table");
  ASSERT_EQ(t.at("all_soft").at("judged").get<int>(), 20);
  ASSERT_EQ(t.at("good").at("judged").get<int>(), 300);
  EXPECT_GE(t.at("all_soft").at("rejected").get<int>(), 19) << t.dump(1);
  EXPECT_LE(t.at("good").at("rejected").get<double>(), 0.003 * 300) << t.dump(1);
  std::cout << "three_soft rejected " << t.at("three_soft").at("rejected").get<int>() << " of "
            << t.at("three_soft").at("judged").get<int>() << "\n";
  for (const auto& teach : j.at("teach")) {
    const auto& e = teach.at("expected_false_reject");
    ASSERT_TRUE(e.is_object()) << teach.dump(1);
    EXPECT_LE(e.at("value").get<double>(), 0.003) << teach.dump(1);
  }
}

// The transition sweep of part 2, taught with `extra` teach arguments.
nlohmann::json PodSweep(IndependentPopulation& t, const std::string& name,
                        const std::vector<std::string>& extra) {
  std::vector<std::string> args = {
      "--seeds",    "303",  "--good",       "0",
      "--one-soft", "100",  "--three-soft", "0",
      "--all-soft", "200",  "--loss-lo",    "0.88",
      "--loss-hi",  "0.99", "--hits",       (t.dir() / (name + ".csv")).string()};
  for (const std::string& e : extra) args.push_back("--teach-arg=" + e);
  return t.Rejects(name, args);
}

// Teaching by physics (the default) against the even split on the same transition sweep: the
// budget given to f0, the residue and the bond index must find more all-ten-soft rotors, and
// never fewer single soft magnets (a default that fell back to the even split fails here).
// Since the second-mode test, single soft magnets are found alike by both (42 / 42 of 200):
// its chi2 drop is far beyond either bound when it shows at all.
// The physics sweep is the default teaching's, so it also gives the all-magnets a90/95 from
// hit/miss (one sweep for both claims: each costs some 25 s).
TEST_F(IndependentPopulation, AllMagnetsA9095AndPhysicsAllocationFindsMoreThanEvenSplit) {
  const nlohmann::json phys = PodSweep(*this, "phys", {});
  const nlohmann::json even = PodSweep(*this, "even", {"--allocation", "even"});
  ASSERT_TRUE(phys.is_object() && even.is_object());
  const auto& pod = phys.at("pod");
  ASSERT_TRUE(pod.is_object()) << phys.dump(1);
  const auto& all = pod.at("all_soft");
  ASSERT_TRUE(all.at("usable").get<bool>()) << all.dump(1);
  ASSERT_FALSE(all.at("a90_95_lr").is_null()) << all.dump(1);
  EXPECT_LE(all.at("a90_95_lr").get<double>(), 0.95) << all.dump(1);
  EXPECT_GT(all.at("a90_95_lr").get<double>(), all.at("a90").get<double>());
  for (const char* cls : {"all_soft", "one_soft"})
    std::cout << cls << ": " << pod.at(cls).at("message").get<std::string>() << "\n";

  auto rejected = [](const nlohmann::json& j, const char* cls) {
    return j.at("table").at(cls).at("rejected").get<int>();
  };
  std::cout << "rejected by physics / even: all_soft " << rejected(phys, "all_soft") << " / "
            << rejected(even, "all_soft") << ", one_soft " << rejected(phys, "one_soft") << " / "
            << rejected(even, "one_soft") << "\n";
  EXPECT_GT(rejected(phys, "all_soft"), rejected(even, "all_soft"));
  EXPECT_GE(rejected(phys, "one_soft"), rejected(even, "one_soft"));
}

// Part 4: the same teaching and judging with and without the residue's limits (the residue
// itself and the bond index, which carries it: analysis/qc/bond_index.h).
TEST_F(IndependentPopulation, ResidueCatchesSofterBondsThanTheResonanceAlone) {
  std::ifstream in(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  nlohmann::json recipe = nlohmann::json::parse(in);
  auto& limits = recipe.at("limits");
  const auto before = limits.size();
  limits.erase(std::remove_if(limits.begin(), limits.end(),
                              [](const nlohmann::json& l) {
                                return l.at("name") == "motional_residue_ohm_per_s" ||
                                       l.at("name") == "bond_index_pct";
                              }),
               limits.end());
  ASSERT_EQ(limits.size() + 2, before) << "the shipped recipe must declare residue and index";
  recipe.erase("bond_index");
  const std::string without = (dir() / "without_residue.json").string();
  std::ofstream(without) << recipe.dump(2);
  const std::vector<std::string> sweep = {
      "--seeds", "404",        "--good", "0",         "--one-soft", "0",         "--three-soft",
      "0",       "--all-soft", "80",     "--loss-lo", "0.85",       "--loss-hi", "0.94"};
  const nlohmann::json with_j = Rejects("with", sweep);
  const nlohmann::json without_j = Rejects("without", sweep, without);
  ASSERT_TRUE(with_j.is_object() && without_j.is_object());
  const int with_n = with_j.at("table").at("all_soft").at("rejected").get<int>();
  const int without_n = without_j.at("table").at("all_soft").at("rejected").get<int>();
  std::cout << "all ten soft (loss 0.85-0.94) rejected with / without the residue: " << with_n
            << " / " << without_n << " of 80\n";
  EXPECT_GE(with_n, without_n + 6);
}

// Part 5. Without the pressure the golden units are read from their CSV files and would get
// masks; the analyze outputs read with it carry no curve, so both are taught without masks.
TEST_F(IndependentPopulation, ClampPressureNormalisationIsTaughtAndNeverCatchesFewer) {
  const std::vector<std::string> sweep = {
      "--seeds", "505",        "--good", "100",       "--one-soft", "0",         "--three-soft",
      "0",       "--all-soft", "60",     "--loss-lo", "0.88",       "--loss-hi", "0.96"};
  std::vector<std::string> with_args = sweep, without_args = sweep;
  with_args.push_back("--clamp-pressure");
  without_args.push_back("--teach-arg=--mask-segments=0");
  const nlohmann::json with_j = Rejects("pressure", with_args);
  const nlohmann::json without_j = Rejects("no_pressure", without_args);
  ASSERT_TRUE(with_j.is_object() && without_j.is_object());
  const nlohmann::json& taught = with_j.at("teach").at(0).at("f0_pressure");
  std::cout << "with the pressure: " << taught.at("note").get<std::string>() << "\n";
  EXPECT_TRUE(taught.at("used").get<bool>());
  EXPECT_NEAR(taught.at("slope").get<double>(), 0.114,
              4.0 * taught.at("slope_sigma").get<double>());
  EXPECT_FALSE(without_j.at("teach").at(0).at("f0_pressure").at("used").get<bool>());
  auto rejected = [](const nlohmann::json& j, const char* cls) {
    return j.at("table").at(cls).at("rejected").get<int>();
  };
  std::cout << "rejected with / without the pressure: all_soft " << rejected(with_j, "all_soft")
            << " / " << rejected(without_j, "all_soft") << " of 60, good "
            << rejected(with_j, "good") << " / " << rejected(without_j, "good") << " of 100\n";
  EXPECT_GE(rejected(with_j, "all_soft"), rejected(without_j, "all_soft"));
  EXPECT_LE(rejected(with_j, "good"), rejected(without_j, "good"));
}

}  // namespace
}  // namespace eol::testing
