// `eol teach` through the built binary: golden FRFs made by `eol simulate` (the default motor,
// different noise seeds and magnet defects), a new recipe version with its hash, refusal to
// overwrite, limits that pass a fresh good unit and fail a poorly cemented one, and errors
// that name the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "../support/child_process.h"
#include "db/test_record.h"
#include "station/daemon/recipe.h"
#include "tests/support/eol_cli.h"
#include "tests/support/pass_records.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

const std::string kMotor = std::string(EOL_SOURCE_DIR) + "/recipes/motors/pmsm-10pole.json";
const std::string kRecipe = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";

using eol::testing::CliRun;

CliRun Eol(std::vector<std::string> args, bool merge_stderr = true) {
  return testing::RunEol(std::move(args), merge_stderr, 300s);
}

std::string Simulated(const eol::testing::TempDir& dir, const std::string& name, int seed,
                      const std::string& defect, double noise_scale,
                      const std::string& motor = kMotor) {
  const std::string out = dir / name;
  const CliRun r =
      Eol({"simulate", "--motor", motor, "--out", out, "--defect", defect, "--seed",
           std::to_string(seed), "--recipe", kRecipe, "--model", "steady_state", "--noise-v",
           std::to_string(2e-3 * noise_scale), "--noise-a", std::to_string(1e-3 * noise_scale)});
  EXPECT_EQ(r.code, 0) << r.out;
  return out;
}

class TeachCli : public ::testing::Test {
 protected:
  void SetUp() override {
    // Spread among the golden units: noise, at four levels (the same motor otherwise).
    for (int i = 0; i < 12; ++i)
      golden_.push_back(
          Simulated(dir_, "g" + std::to_string(i) + ".csv", 100 + i, "none", 1.0 + 0.5 * (i % 4)));
  }
  std::vector<std::string> TeachArgs(const std::string& out) {
    // 12 units: fewer than the method needs for the default budget, so forced.
    std::vector<std::string> a = {"teach", "--recipe",          kRecipe,   "--out",
                                  out,     "--allow-few-units", "--golden"};
    a.insert(a.end(), golden_.begin(), golden_.end());
    return a;
  }
  eol::testing::TempDir dir_;
  std::vector<std::string> golden_;
};

TEST_F(TeachCli, WritesANewVersionAndRefusesToOverwrite) {
  const std::string out = dir_ / "taught.json";
  CliRun r = Eol(TeachArgs(out));
  ASSERT_EQ(r.code, 0) << r.out;
  const station::Recipe before = station::LoadRecipe(kRecipe);
  const station::Recipe after = station::LoadRecipe(out);
  EXPECT_EQ(after.version, before.version + 1);
  EXPECT_EQ(after.id, before.id);
  EXPECT_NE(after.hash, before.hash);
  EXPECT_NE(r.out.find("sha256 " + after.hash), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("units needed for the stated confidence:"), std::string::npos);
  // The limits changed to the golden units' spread: f0 limits around the motor's 390 Hz, far
  // narrower than the hand-set 370-420 (the golden units differ by noise only).
  const auto& f0 = after.limits[0];
  ASSERT_EQ(f0.name, "resonance_f_hz");
  EXPECT_GT(*f0.limit.lo, 380.0);
  EXPECT_LT(*f0.limit.hi, 400.0);
  EXPECT_LT(*f0.limit.lo, 390.0);
  EXPECT_GT(*f0.limit.hi, 389.0);
  // Masks below and above the resonance band (the scalar limits judge the band itself).
  ASSERT_EQ(after.masks.size(), 2u);
  EXPECT_EQ(after.masks[0].name, "re_z_taught_below");
  EXPECT_EQ(after.masks[1].name, "re_z_taught_above");
  EXPECT_LT(after.masks[0].points.back().f_hz, 385.0);
  EXPECT_GT(after.masks[1].points.front().f_hz, 395.0);

  // Never overwrite silently.
  const auto mtime = std::filesystem::last_write_time(out);
  r = Eol(TeachArgs(out));
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(out + " exists: refusing to overwrite"), std::string::npos) << r.out;
  EXPECT_EQ(std::filesystem::last_write_time(out), mtime);
  std::vector<std::string> forced = TeachArgs(out);
  forced.push_back("--force");
  r = Eol(forced);
  EXPECT_EQ(r.code, 0) << r.out;

  // A fresh good unit passes the taught recipe; one with every magnet poorly cemented fails.
  const std::string fresh = Simulated(dir_, "fresh.csv", 999, "none", 1.0);
  r = Eol({"analyze", "--measured", fresh, "--recipe", out, "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.out)["verdict"]["outcome"], "PASS") << r.out;
  const std::string bad = Simulated(dir_, "bad.csv", 998, "all_soft", 1.0);
  r = Eol({"analyze", "--measured", bad, "--recipe", out, "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.out)["verdict"]["outcome"], "FAIL") << r.out;
}

TEST_F(TeachCli, ReadsAnalyzeJsonAndReportsJson) {
  std::vector<std::string> args = {
      "teach",  "--recipe",          kRecipe,   "--out", dir_ / "j.json",
      "--json", "--allow-few-units", "--golden"};
  for (std::size_t i = 0; i < 6; ++i) {
    const CliRun a =
        Eol({"analyze", "--measured", golden_[i], "--recipe", kRecipe, "--json"}, false);
    ASSERT_EQ(a.code, 0) << a.out;
    const std::string path = dir_ / ("a" + std::to_string(i) + ".json");
    std::ofstream(path) << a.out;
    args.push_back(path);
  }
  const CliRun r = Eol(args, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["units_used"], 6);
  EXPECT_EQ(j["recipe"]["version"], 2);
  EXPECT_EQ(j["masks"].size(), 0u);  // no curves in analyze --json: the recipe's mask stays
  EXPECT_EQ(station::LoadRecipe(dir_ / "j.json").masks[0].name, "re_z_low_band");
  EXPECT_GT(j["units_needed"].get<int>(), 6);
}

// `eol export --format records` records: PASS production records of this recipe are golden
// units; a FAIL, ERROR or ABORTED record, a master's self-check and a record of another recipe
// hash are refused, naming the record.
TEST_F(TeachCli, ReadsExportedRecordsAndRefusesWhatIsNotAGoodUnit) {
  const std::string hash = station::LoadRecipe(kRecipe).hash;
  auto records = [&](auto spoil) {
    std::vector<db::TestRecord> units = testing::PassRecords(hash, 10);
    spoil(units[4]);
    const nlohmann::json list = units;
    const std::string path = dir_ / "export.json";
    std::ofstream(path) << list.dump(1);
    return path;
  };
  auto teach = [&](const std::string& path) {
    return Eol({"teach", "--recipe", kRecipe, "--out", dir_ / "e.json", "--force",
                "--allow-few-units", "--golden", path});
  };
  std::string path = records([](db::TestRecord&) {});
  CliRun r = teach(path);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("10 of 10 golden units used"), std::string::npos) << r.out;
  const station::Recipe taught = station::LoadRecipe(dir_ / "e.json");
  EXPECT_LT(*taught.limits[0].limit.lo, 388.6);
  EXPECT_GT(*taught.limits[0].limit.hi, 391.4);
  EXPECT_NE(taught.description.find("FORCED: 10 golden units"), std::string::npos);

  for (auto outcome :
       {analysis::Outcome::kFail, analysis::Outcome::kError, analysis::Outcome::kAborted}) {
    path = records([&](db::TestRecord& rec) { rec.outcome = outcome; });
    r = teach(path);
    EXPECT_EQ(r.code, 2) << r.out;
    EXPECT_NE(r.out.find("record " + path + "[4] SN4 is " + analysis::ToString(outcome) +
                         ": only PASS records are golden units"),
              std::string::npos)
        << r.out;
  }
  path = records([](db::TestRecord& rec) { rec.kind = db::RecordKind::kSelfCheck; });
  r = teach(path);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("SN4 is a self_check test (a master part)"), std::string::npos) << r.out;
  path = records([](db::TestRecord& rec) { rec.recipe_hash = "abc123"; });
  r = teach(path);
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("SN4 was tested with recipe hash abc123, not " + hash), std::string::npos)
      << r.out;
}

// Known-bad units (`--bad`): one with every magnet poorly cemented is caught by the limits the
// budget sets; a unit an engineer marked bad that measures like the good ones passes any limit
// within the budget, and teach says so by name (text and JSON). The even split has no share to
// move and refuses known-bad units.
TEST_F(TeachCli, KnownBadUnitsAreReportedWithTheirEscapes) {
  const std::string caught = Simulated(dir_, "bad-all-soft.csv", 997, "all_soft", 1.0);
  const std::string hidden = Simulated(dir_, "bad-hidden.csv", 996, "none", 1.0);
  std::vector<std::string> args = TeachArgs(dir_ / "kb.json");
  args.insert(args.end(), {"--bad", caught, hidden, "--json"});
  CliRun r = Eol(args, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("known_bad")) << r.out;
  EXPECT_EQ(j["known_bad"]["units"], 2);
  EXPECT_EQ(j["known_bad"]["escapes"], nlohmann::json::array({hidden})) << r.out;
  EXPECT_NE(
      j["message"].get<std::string>().find("no bound within the budget catches them: " + hidden),
      std::string::npos)
      << r.out;
  std::vector<std::string> text = TeachArgs(dir_ / "kb-text.json");
  text.insert(text.end(), {"--bad", caught, hidden});
  r = Eol(text);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("known-bad unit passes: " + hidden), std::string::npos) << r.out;
  std::vector<std::string> even = TeachArgs(dir_ / "kb-even.json");
  even.insert(even.end(), {"--bad", caught, "--allocation", "even"});
  r = Eol(even);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("known-bad units need allocation physics"), std::string::npos) << r.out;
}

// Issue 37: golden units of another motor (a stiffer fixture: the rotor rings about 50 % higher;
// a winding of 2.4 times the resistance) are refused on the ten-pole recipe, naming each
// quantity that disagrees and by how much; --force-foreign teaches from them, the taught
// recipe records it, and the winding-temperature reference is relearned from them (with a
// warning: the old 0.5 ohm read them as hundreds of degC), so a fresh unit of that motor
// passes the taught recipe instead of ERROR "winding temperature".
TEST_F(TeachCli, RefusesGoldenUnitsOfAnotherMotorUnlessForcedAndRelearnsTheWindingReference) {
  nlohmann::json motor = nlohmann::json::parse(std::ifstream(kMotor));
  motor["id"] = "other-motor";
  motor["electrical"]["r_ohm"] = 1.2;
  motor["fixture"]["stiffness_nm_per_rad"] =
      2.5 * motor["fixture"]["stiffness_nm_per_rad"].get<double>();
  const std::string other = dir_ / "other-motor.json";
  std::ofstream(other) << motor.dump(2);
  std::vector<std::string> args = {"teach",         "--recipe",          kRecipe,   "--out",
                                   dir_ / "o.json", "--allow-few-units", "--golden"};
  for (int i = 0; i < 12; ++i)
    args.push_back(Simulated(dir_, "o" + std::to_string(i) + ".csv", 300 + i, "none", 1.0, other));
  CliRun r = Eol(args);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("eol teach: refused: the golden units are not recipe pmsm-10pole's motor: "
                       "resonance_f_hz: the golden units' median "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("% from the recipe's 395 Hz (more than 15 %)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("winding_r_ohm: the golden units' median 1.2"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find(" x above the recipe's 0.5 ohm (more than a factor 1.5)"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("--force-foreign"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "o.json"));

  // Forced. Golden units that differ by noise alone leave f0 so steady that the bond index's
  // exponent leaves its valid range; that index is not this test's subject, so the forced
  // teaching uses the ten-pole recipe without it.
  nlohmann::json no_index = nlohmann::json::parse(std::ifstream(kRecipe));
  no_index.erase("bond_index");
  nlohmann::json& limits = no_index["limits"];
  limits.erase(
      std::remove_if(limits.begin(), limits.end(),
                     [](const nlohmann::json& l) { return l["name"] == "bond_index_pct"; }),
      limits.end());
  std::ofstream(dir_ / "no-index.json") << no_index.dump(2);
  args[2] = dir_ / "no-index.json";
  args.push_back("--force-foreign");
  r = Eol(args);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("eol teach: warning: forced (--force-foreign)"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("eol teach: warning: the recipe's "
                       "/conditions/winding_temperature_c/r_ref_ohm 0.5000 ohm read its golden "
                       "units as "),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("Winding reference r_ref_ohm relearned: 0.5000 -> 1.2"), std::string::npos)
      << r.out;
  const station::Recipe taught = station::LoadRecipe(dir_ / "o.json");
  EXPECT_NEAR(taught.conditions.r_ref_ohm, 1.2, 0.03);
  EXPECT_NE(taught.description.find("FORCED (--force-foreign): golden units of another motor"),
            std::string::npos)
      << taught.description;
  ASSERT_TRUE(taught.approval.has_value());
  EXPECT_EQ(taught.approval->note,
            "taught from golden units of another motor, forced (--force-foreign)");
  const std::string fresh = Simulated(dir_, "o-fresh.csv", 399, "none", 1.0, other);
  r = Eol({"analyze", "--measured", fresh, "--recipe", dir_ / "o.json", "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_EQ(nlohmann::json::parse(r.out)["verdict"]["outcome"], "PASS") << r.out;
  r = Eol({"analyze", "--measured", fresh, "--recipe", kRecipe, "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;  // the untaught recipe: another motor's winding reference
  EXPECT_NE(r.out.find("condition out of window: winding temperature 3"), std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("against the recipe's r_ref_ohm 0.5000 ohm at 20.0 degC: implausible for "
                       "any winding, the reference is likely another motor's"),
            std::string::npos)
      << r.out;
}

TEST_F(TeachCli, ErrorsNameTheFile) {
  const std::string junk = dir_ / "junk.json";
  std::ofstream(junk) << "{\"hello\": 1}";
  CliRun r = Eol({"teach", "--recipe", kRecipe, "--out", dir_ / "x.json", "--golden", junk});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(junk), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.json"));
  r = Eol(
      {"teach", "--recipe", kRecipe, "--out", dir_ / "x.json", "--golden", golden_[0], golden_[1]});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("too few golden units"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.json"));
  // Twelve units are fewer than the default budget needs: refused without --allow-few-units.
  std::vector<std::string> args = {"teach", "--recipe",      kRecipe,
                                   "--out", dir_ / "x.json", "--golden"};
  args.insert(args.end(), golden_.begin(), golden_.end());
  r = Eol(args);
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("too few golden units: 12 used, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("--allow-few-units"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.json"));
}

}  // namespace
}  // namespace eol
