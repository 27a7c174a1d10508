// `eol calibrate` through the built binary against the sim DAQ with a reference resistor in
// the fixture and injected channel errors (gain 1.03 on the voltage channel, the current
// channel 20 us late): the written calibration recovers both within three of its sigmas and
// corrects the shunt; a wrong --reference-ohm writes nothing and says why. The station config
// then names the file (relative to the config): the DAQ reports the measured calibration and
// a test the station runs stores it (method, date, R_ref) in its record.
#include <gtest/gtest.h>

#include <fstream>

#include "../support/child_process.h"
#include "drivers/daq/calibration_file.h"
#include "drivers/factory/factory.h"
#include "station/daemon/config.h"
#include "station/daemon/station.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::TempDir;

using eol::testing::CliRun;

CliRun Calibrate(std::vector<std::string> args) {
  args.insert(args.begin(), "calibrate");
  return testing::RunEol(std::move(args), true, 120s);
}

nlohmann::json StationJson(const TempDir& dir, nlohmann::json daq) {
  return {{"station_id", "cal-1"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "station.sqlite"},
          {"fixture", {{"driver", "sim"}}},
          {"daq", std::move(daq)}};
}

void WriteJson(const std::string& path, const nlohmann::json& j) {
  std::ofstream(path) << j.dump(2);
}

const nlohmann::json kReferenceDaq = {{"driver", "sim"},
                                      {"load", "reference_resistor"},
                                      {"reference_ohm", 2.0},
                                      {"injected_gain", 1.03},
                                      {"injected_channel_delay_s", 20e-6}};

TEST(CalibrateCli, RecoversInjectedGainAndDelayWithinThreeSigma) {
  TempDir dir;
  WriteJson(dir / "station.json", StationJson(dir, kReferenceDaq));
  const CliRun r = Calibrate({"--config", dir / "station.json", "--reference-ohm", "2.0", "--out",
                              dir / "calibration.json"});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("calibration " + (dir / "calibration.json") + ": gain"), std::string::npos)
      << r.out;
  const nlohmann::json j = io::ReadJsonFile(dir / "calibration.json");
  const nlohmann::json& e = j["estimate"];
  const double gain = e["gain"], gain_sigma = e["gain_sigma"];
  const double delay = e["delay_s"], delay_sigma = e["delay_sigma_s"];
  std::printf("gain %.6f +- %.6f, delay %.3f +- %.3f us\n", gain, gain_sigma, delay * 1e6,
              delay_sigma * 1e6);
  EXPECT_NEAR(gain, 1.03, 3 * gain_sigma);
  EXPECT_NEAR(delay, 20e-6, 3 * delay_sigma);
  // Sigmas small enough for the check to mean something.
  EXPECT_LT(gain_sigma, 0.002);
  EXPECT_LT(delay_sigma, 2e-6);
  EXPECT_GT(gain_sigma, 0.0);
  EXPECT_GT(delay_sigma, 0.0);
  EXPECT_NEAR(j["shunt_ohm"].get<double>(), 0.1 / gain, 1e-12);
  EXPECT_DOUBLE_EQ(j["channel_delay_s"].get<double>(), delay);
  EXPECT_EQ(j["method"], "reference_resistor");
  EXPECT_EQ(j["reference_ohm"], 2.0);
  const std::string date = j["date"];  // UTC ISO 8601: 2026-11-22T07:30:00.123Z
  EXPECT_TRUE(date.size() >= 20 && date[4] == '-' && date[10] == 'T' && date.back() == 'Z') << date;

  // The station config names the file, relative to itself: the DAQ reports it.
  nlohmann::json daq = {{"driver", "sim"}, {"calibration_file", "calibration.json"}};
  WriteJson(dir / "station2.json", StationJson(dir, daq));
  const station::StationConfig config = station::LoadStationConfig(dir / "station2.json");
  const drivers::DriverSet set = drivers::MakeDrivers(config.drivers);
  const drivers::Calibration c = set.daq->calibration();
  EXPECT_EQ(c.method, "reference_resistor");
  EXPECT_EQ(c.date, j["date"].get<std::string>());
  EXPECT_DOUBLE_EQ(c.reference_ohm, 2.0);
  EXPECT_DOUBLE_EQ(c.shunt_ohm, j["shunt_ohm"].get<double>());

  // A test run by the station stores it in the record.
  station::Station st(config);
  const db::TestRecord record = st.RunTest("SN-CAL-1");
  EXPECT_EQ(record.calibration["method"], "reference_resistor") << record.calibration.dump();
  EXPECT_EQ(record.calibration["reference_ohm"], 2.0);
  EXPECT_EQ(record.calibration["date"], j["date"]);
  EXPECT_EQ(record.calibration["shunt_ohm"], j["shunt_ohm"]);
  EXPECT_EQ(record.calibration["daq"], "sim");
}

TEST(CalibrateCli, WrongReferenceWritesNothing) {
  TempDir dir;
  WriteJson(dir / "station.json", StationJson(dir, kReferenceDaq));
  const CliRun r = Calibrate({"--config", dir / "station.json", "--reference-ohm", "20", "--out",
                              dir / "calibration.json"});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("wrong reference_ohm"), std::string::npos) << r.out;
  EXPECT_FALSE(std::filesystem::exists(dir / "calibration.json"));
}

TEST(CalibrateCli, BadCalibrationFileIsNamed) {
  TempDir dir;
  WriteJson(dir / "bad.json", {{"shunt_ohm", -1.0}});
  nlohmann::json daq = {{"driver", "sim"}, {"calibration_file", "bad.json"}};
  WriteJson(dir / "station.json", StationJson(dir, daq));
  const station::StationConfig config = station::LoadStationConfig(dir / "station.json");
  try {
    drivers::MakeDrivers(config.drivers);
    FAIL() << "a negative shunt was accepted";
  } catch (const io::ConfigError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("/daq/calibration_file"), std::string::npos) << m;
    EXPECT_NE(m.find(dir / "bad.json"), std::string::npos) << m;
    EXPECT_NE(m.find("/shunt_ohm: must be positive"), std::string::npos) << m;
  }
  // A measured calibration without its date is refused too.
  WriteJson(dir / "bad.json", {{"method", "reference_resistor"}, {"reference_ohm", 1.0}});
  try {
    drivers::MakeDrivers(config.drivers);
    FAIL() << "a reference_resistor calibration without a date was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/date: a reference_resistor calibration needs its date"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eol
