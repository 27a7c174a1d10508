// One judge (station/daemon/judge.h): a recording judged by the running station (the real sequencer
// on the simulated fixture, the recording replayed by the replay DAQ, a real SQLite file) and
// the same recording judged offline by `eol analyze --recipe R --measured FILE --json` get the
// same outcome, the same measurements with the same values, and the same reasons (code and
// text). One recipe per way a verdict is reached: PASS, FAIL by a limit, FAIL by a curve
// mask, ERROR by a test condition.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <memory>

#include "../support/child_process.h"
#include "../support/eol_cli.h"
#include "analysis/sim/population.h"
#include "db/store.h"
#include "drivers/factory/factory.h"
#include "drivers/io/json_config.h"
#include "drivers/io/recording_files.h"
#include "station/daemon/recipe.h"
#include "station/daemon/sequencer.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
using analysis::Outcome;
using analysis::ReasonCode;
using eol::testing::RunEol;
using eol::testing::TempDir;

class JudgeParityTest : public ::testing::Test {
 protected:
  // One simulated recording shared by every case (`eol simulate` takes a while).
  static void SetUpTestSuite() {
    dir_ = new TempDir();
    const auto r = RunEol(
        {"simulate", "--motor", std::string(EOL_SOURCE_DIR) + "/recipes/motors/pmsm-10pole.json",
         "--recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json", "--format",
         "recording", "--model", "steady_state", "--seed", "7", "--out", *dir_ / "unit.csv"},
        true, 120s);
    ASSERT_EQ(r.code, 0) << r.out;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  static nlohmann::json BaseRecipe() {
    return io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  }

  // Judges the recording on the station and offline with `recipe`, checks they agree and
  // returns the station's record.
  // With `with_pressure` the offline judge gets the clamp pressure the station read
  // (--clamp-pressure-bar, written to round-trip to the same double).
  // `recording_file` (in the suite's folder) is replayed; `exit_code` is eol analyze's (1: the
  // recording cannot be analysed).
  db::TestRecord JudgeBothWays(const std::string& name, const nlohmann::json& recipe_json,
                               bool with_pressure = false,
                               const std::string& recording_file = "unit.csv", int exit_code = 0) {
    const std::string recipe_path = *dir_ / (name + ".json");
    std::ofstream(recipe_path) << recipe_json.dump(2);
    const Recipe recipe = LoadRecipe(recipe_path);
    const std::string recording = *dir_ / recording_file;

    const nlohmann::json sim = {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}};
    auto bench = std::make_shared<drivers::SimBench>(
        drivers::ParseSimBenchSettings(io::JsonObject(sim, "/sim")));
    drivers::DriverSet set = drivers::MakeDrivers(
        {{"fixture", {{"driver", "sim"}}},
         {"daq", {{"driver", "replay"}, {"file", recording}, {"repeat", true}}},
         {"sim", sim}},
        bench);
    EXPECT_TRUE(set.fixture->Connect().ok());
    EXPECT_TRUE(set.daq->Connect().ok());
    auto store = db::Store::Open(*dir_ / (name + ".sqlite"));
    StatusBoard board("parity");
    const std::string serial = "PARITY-" + name;
    bench->LoadUnit(analysis::DrawUnit(bench->settings().population, serial, false));
    Sequencer sequencer(*set.fixture, *set.daq, *store, std::make_shared<const Recipe>(recipe),
                        board, SequencerOptions{});
    const db::TestRecord station = sequencer.RunTest(serial);

    std::vector<std::string> args = {"analyze",    "--recipe", recipe_path,
                                     "--measured", recording,  "--json"};
    if (with_pressure) {
      args.push_back("--clamp-pressure-bar");
      args.push_back(nlohmann::json(station.conditions.clamp_pressure_bar.value()).dump());
    }
    const auto cli = RunEol(args, false, 120s);
    EXPECT_EQ(cli.code, exit_code) << cli.out;  // 0: analysed, whatever the verdict
    nlohmann::json offline;
    try {
      offline = nlohmann::json::parse(cli.out);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "eol analyze printed no JSON: " << e.what() << "\n" << cli.out;
      return station;
    }
    const nlohmann::json& v = offline.at("verdict");
    EXPECT_EQ(v.at("outcome").get<std::string>(), analysis::ToString(station.outcome)) << name;
    // The same reasons: codes and texts, in the same order.
    EXPECT_EQ(v.at("reasons"), nlohmann::json(station.reasons)) << name;
    // The same measurements, the same values to the last bit (the same samples, the same code).
    const nlohmann::json& ms = v.at("measurements");
    EXPECT_EQ(ms.size(), station.measurements.size()) << name;
    for (std::size_t i = 0; i < std::min(ms.size(), station.measurements.size()); ++i) {
      const analysis::Measurement& m = station.measurements[i];
      EXPECT_EQ(ms[i].at("name").get<std::string>(), m.name) << name;
      EXPECT_EQ(ms[i].at("outcome").get<std::string>(), analysis::ToString(m.outcome))
          << name << " " << m.name;
      if (std::isfinite(m.value)) {
        EXPECT_EQ(ms[i].at("value").get<double>(), m.value) << name << " " << m.name;
      }
    }
    // The conditions the judge computed from the recording agree too, in the record's JSON.
    const nlohmann::json conditions = station.conditions;
    for (const char* key : {"excitation_v_rms", "excitation_a_rms", "winding_temperature_c"})
      if (conditions.contains(key)) {
        EXPECT_EQ(offline.at("conditions").at(key), conditions.at(key)) << key;
      }
    return station;
  }

  static bool HasCode(const db::TestRecord& r, ReasonCode code) {
    for (const analysis::Reason& reason : r.reasons)
      if (reason.code == code) return true;
    return false;
  }

  static TempDir* dir_;
};

TempDir* JudgeParityTest::dir_ = nullptr;

TEST_F(JudgeParityTest, Pass) {
  const db::TestRecord r = JudgeBothWays("pass", BaseRecipe());
  EXPECT_EQ(r.outcome, Outcome::kPass) << nlohmann::json(r.reasons).dump();
  EXPECT_TRUE(r.reasons.empty());
}

TEST_F(JudgeParityTest, FailByLimit) {
  nlohmann::json j = BaseRecipe();
  for (auto& l : j["limits"])
    if (l["name"] == "resonance_f_hz") l["lo"] = 400.0;  // the unit's mode is near 390 Hz
  const db::TestRecord r = JudgeBothWays("limit", j);
  EXPECT_EQ(r.outcome, Outcome::kFail);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().code, ReasonCode::kLimit);
  EXPECT_FALSE(HasCode(r, ReasonCode::kMask));
}

TEST_F(JudgeParityTest, FailByMask) {
  nlohmann::json j = BaseRecipe();
  // Re Z of a 0.5 ohm winding cannot stay below 0.3 ohm from 300 to 365 Hz.
  j["masks"][0]["points"] = {{{"f_hz", 300}, {"hi", 0.3}}, {{"f_hz", 365}, {"hi", 0.3}}};
  const db::TestRecord r = JudgeBothWays("mask", j);
  EXPECT_EQ(r.outcome, Outcome::kFail);
  EXPECT_TRUE(HasCode(r, ReasonCode::kMask)) << nlohmann::json(r.reasons).dump();
  EXPECT_FALSE(HasCode(r, ReasonCode::kLimit)) << nlohmann::json(r.reasons).dump();
}

TEST_F(JudgeParityTest, ErrorByCondition) {
  nlohmann::json j = BaseRecipe();
  j["conditions"]["excitation_v_rms"] = {{"lo", 5.0}, {"hi", 6.0}};
  const db::TestRecord r = JudgeBothWays("condition", j);
  EXPECT_EQ(r.outcome, Outcome::kError);
  ASSERT_FALSE(r.reasons.empty());
  EXPECT_EQ(r.reasons.front().code, ReasonCode::kCondition);
  EXPECT_EQ(r.reasons.front().text.rfind("condition out of window: excitation level ", 0), 0u)
      << r.reasons.front().text;
}

// A recording whose current clipped the DAQ's range (the file does not state the range: the
// samples repeat at the rail) is ERROR "clipped" on the station and offline alike, with the
// same reason and no measurement (nothing was fitted).
TEST_F(JudgeParityTest, ErrorByClipping) {
  analysis::Recording rec = io::ReadRecordingCsv(*dir_ / "unit.csv");
  double peak = 0.0;
  for (double i : rec.current_a) peak = std::max(peak, std::abs(i));
  for (double& i : rec.current_a) i = std::clamp(i, -0.7 * peak, 0.7 * peak);
  io::WriteRecordingCsv(*dir_ / "clipped.csv", rec);
  const db::TestRecord r = JudgeBothWays("clipped", BaseRecipe(), false, "clipped.csv", 1);
  EXPECT_EQ(r.outcome, Outcome::kError);
  ASSERT_EQ(r.reasons.size(), 1u) << nlohmann::json(r.reasons).dump();
  EXPECT_EQ(r.reasons.front().code, ReasonCode::kClipped);
  EXPECT_EQ(r.reasons.front().text.rfind("invalid measurement: current clipped at ", 0), 0u)
      << r.reasons.front().text;
  EXPECT_NE(r.reasons.front().text.find(" A: "), std::string::npos) << r.reasons.front().text;
}

// The resonance at the reference clamp pressure (analysis/qc/f0_pressure.h) is judged from the
// pressure read at clamp confirmation on the station and from --clamp-pressure-bar offline:
// the same value to the bit; offline without the pressure it is ERROR, with a reason that says
// where the pressure comes from.
TEST_F(JudgeParityTest, FailByPressureNormalisedResonance) {
  nlohmann::json j = BaseRecipe();
  j["f0_pressure"] = {{"exponent", 0.11}, {"pressure_ref_bar", 4.0}};
  j["limits"].push_back({{"name", "resonance_f_ref_pressure_hz"}, {"unit", "Hz"}, {"lo", 370.0}});
  const db::TestRecord pass = JudgeBothWays("pressure-pass", j, true);
  EXPECT_EQ(pass.outcome, Outcome::kPass) << nlohmann::json(pass.reasons).dump();
  const double p = pass.conditions.clamp_pressure_bar.value();
  double f0 = 0.0, f0p = 0.0;
  for (const analysis::Measurement& m : pass.measurements) {
    if (m.name == "resonance_f_hz") f0 = m.value;
    if (m.name == "resonance_f_ref_pressure_hz") f0p = m.value;
  }
  // 5.5 bar on the simulated clamp, 4.0 the reference: about 3.6 % lower than f0.
  EXPECT_NEAR(p, 5.5, 0.05);
  EXPECT_NEAR(f0p, f0 * std::pow(4.0 / p, 0.11), 1e-9 * f0);

  j["limits"].back()["lo"] = f0p + 1.0;  // between f0p and f0: only the normalised one fails
  const db::TestRecord fail = JudgeBothWays("pressure-fail", j, true);
  EXPECT_EQ(fail.outcome, Outcome::kFail);
  ASSERT_FALSE(fail.reasons.empty());
  EXPECT_EQ(fail.reasons.front().text.rfind("resonance_f_ref_pressure_hz = ", 0), 0u)
      << fail.reasons.front().text;

  const std::string recipe_path = *dir_ / "pressure-fail.json";
  const auto cli =
      RunEol({"analyze", "--recipe", recipe_path, "--measured", *dir_ / "unit.csv", "--json"},
             false, 120s);
  const nlohmann::json offline = nlohmann::json::parse(cli.out);
  EXPECT_EQ(offline.at("verdict").at("outcome"), "ERROR");
  EXPECT_NE(offline.at("verdict").at("reasons").dump().find("--clamp-pressure-bar"),
            std::string::npos)
      << offline.at("verdict").at("reasons").dump();
}

}  // namespace
}  // namespace eol::station
