// The replay acquisition driver (drivers/daq/replay_daq.h) with the station's file readers:
// a recording written by `eol simulate --format recording` comes back through the driver and
// analyses to the same resonance as the file read directly (CSV exactly, WAV within the
// float format's rounding), files come in order and then run out, one file repeats, and a
// recording that does not fit the request is refused naming the file.
#include <gtest/gtest.h>

#include <atomic>
#include <fstream>

#include "../support/child_process.h"
#include "analysis/impedance_analysis.h"
#include "drivers/factory/factory.h"
#include "drivers/io/recording_files.h"
#include "station/daemon/recipe.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::TempDir;

struct Fixture {
  TempDir dir;
  station::Recipe recipe =
      station::LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  analysis::Excitation ex = analysis::DesignMultisine(recipe.excitation);
  drivers::AcquisitionRequest req;

  Fixture() {
    req.sample_rate_hz = ex.sample_rate_hz;
    req.period_samples = ex.period_samples;
    req.excitation_v = ex.Repeat(recipe.transient_periods + recipe.periods);
  }
  void Simulate(const std::string& out, const std::string& seed) {
    ChildProcess p({EOL_BINARY, "simulate", "--motor",
                    std::string(EOL_SOURCE_DIR) + "/recipes/motors/pmsm-10pole.json", "--format",
                    "recording", "--model", "steady_state", "--seed", seed, "--out", out});
    ASSERT_EQ(p.Wait(120s).value_or(-1), 0) << p.output();
  }
  std::unique_ptr<drivers::Daq> Replay(const nlohmann::json& daq) {
    auto set = drivers::MakeDrivers({{"fixture", {{"driver", "sim"}}}, {"daq", daq}});
    return std::move(set.daq);
  }
  double F0(const analysis::Recording& rec) {
    const analysis::ImpedanceAnalysis a =
        analysis::AnalyzeRecording(rec, ex.lines, recipe.analysis);
    EXPECT_TRUE(a.usable) << a.message;
    const analysis::FittedParameter* f0 = a.fit.Find("f0_hz");
    return f0 ? f0->value : std::nan("");
  }
};

TEST(ReplayDaq, SimulatedRecordingRoundTripsToTheSameF0) {
  Fixture fx;
  fx.Simulate(fx.dir / "a.csv", "1");
  fx.Simulate(fx.dir / "b.csv", "2");
  const auto direct = io::ReadRecordingCsv(fx.dir / "a.csv");
  analysis::Recording direct_periodic = direct;
  direct_periodic.period_samples = fx.ex.period_samples;
  const double f0_direct = fx.F0(direct_periodic);
  ASSERT_TRUE(std::isfinite(f0_direct));
  EXPECT_NEAR(f0_direct, 390.0, 5.0);  // the default fixture's mode (simulate_cli_test)

  auto daq = fx.Replay({{"driver", "replay"}, {"files", {fx.dir / "a.csv", fx.dir / "b.csv"}}});
  ASSERT_TRUE(daq->Connect().ok());
  const std::atomic<bool> abort{false};
  auto a = daq->Acquire(fx.req, abort);
  ASSERT_TRUE(a.ok()) << a.status().message();
  EXPECT_EQ(a.value().period_samples, fx.ex.period_samples);
  EXPECT_EQ(fx.F0(a.value()), f0_direct);  // the same samples: the same number
  auto b = daq->Acquire(fx.req, abort);
  ASSERT_TRUE(b.ok()) << b.status().message();
  EXPECT_NE(b.value().voltage_v, a.value().voltage_v);  // the second file, another seed
  EXPECT_NEAR(fx.F0(b.value()), f0_direct, 1.0);
  auto c = daq->Acquire(fx.req, abort);
  ASSERT_FALSE(c.ok());
  EXPECT_NE(c.status().message().find("no more recordings: all 2 were replayed"), std::string::npos)
      << c.status().message();

  // WAV (32-bit float, gains 10 V and 2 A per full scale) through a directory listing.
  std::filesystem::create_directory(fx.dir / "wav");
  io::WriteWavRecording(fx.dir / "wav/run1.wav", direct, 10.0, 2.0);
  auto wav = fx.Replay({{"driver", "replay"},
                        {"directory", fx.dir / "wav"},
                        {"gains", {{"voltage_v_per_fs", 10.0}, {"current_a_per_fs", 2.0}}}});
  ASSERT_TRUE(wav->Connect().ok());
  auto w = wav->Acquire(fx.req, abort);
  ASSERT_TRUE(w.ok()) << w.status().message();
  EXPECT_NEAR(fx.F0(w.value()), f0_direct, 0.01);
}

TEST(ReplayDaq, RepeatsOneFileAndRefusesMisfits) {
  Fixture fx;
  fx.Simulate(fx.dir / "a.csv", "1");
  auto daq = fx.Replay({{"driver", "replay"}, {"file", fx.dir / "a.csv"}, {"repeat", true}});
  ASSERT_TRUE(daq->Connect().ok());
  const std::atomic<bool> abort{false};
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(daq->Acquire(fx.req, abort).ok()) << i;

  drivers::AcquisitionRequest longer = fx.req;
  longer.excitation_v = fx.ex.Repeat(fx.recipe.transient_periods + fx.recipe.periods + 1);
  auto r = daq->Acquire(longer, abort);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("recording " + (fx.dir / "a.csv") + ": "), std::string::npos)
      << r.status().message();
  EXPECT_NE(r.status().message().find("samples, the excitation has"), std::string::npos);

  ASSERT_TRUE(daq->Connect().ok());  // out of the error state
  drivers::AcquisitionRequest faster = fx.req;
  faster.sample_rate_hz *= 2.0;
  r = daq->Acquire(faster, abort);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("sample rate 8000"), std::string::npos)
      << r.status().message();

  auto missing = fx.Replay({{"driver", "replay"}, {"files", {fx.dir / "nope.csv"}}});
  const drivers::Status s = missing->Connect();
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("recording " + (fx.dir / "nope.csv") + ": no such file"),
            std::string::npos)
      << s.message();

  try {
    fx.Replay({{"driver", "replay"}, {"file", fx.dir / "a.csv"}, {"directory", fx.dir.path()}});
    FAIL() << "two sources accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/daq: give exactly one of"), std::string::npos)
        << e.what();
  }
}

// Issue 37: the DAQ config states the converter's range of CSV recordings that do not state it
// ("full_scale"), so a replayed recording whose current reaches it is refused as clipped; a
// half-stated range is refused naming the key.
TEST(ReplayDaq, ConfiguredFullScaleReachesTheClippingCheck) {
  Fixture fx;
  fx.Simulate(fx.dir / "a.csv", "3");
  auto daq = fx.Replay({{"driver", "replay"},
                        {"file", fx.dir / "a.csv"},
                        {"repeat", true},
                        {"full_scale", {{"voltage_v", 10.0}, {"current_a", 0.05}}}});
  ASSERT_TRUE(daq->Connect().ok());
  const std::atomic<bool> abort{false};
  auto r = daq->Acquire(fx.req, abort);
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r.value().voltage_full_scale_v, 10.0);
  EXPECT_EQ(r.value().current_full_scale_a, 0.05);
  const analysis::ImpedanceAnalysis a =
      analysis::AnalyzeRecording(r.value(), fx.ex.lines, fx.recipe.analysis);
  EXPECT_FALSE(a.usable);
  EXPECT_TRUE(a.frf.clipped);
  EXPECT_EQ(a.message.rfind("invalid measurement: current clipped at 0.05 A: ", 0), 0u)
      << a.message;
  try {
    fx.Replay(
        {{"driver", "replay"}, {"file", fx.dir / "a.csv"}, {"full_scale", {{"voltage_v", 10.0}}}});
    FAIL() << "a half-stated range was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/daq/full_scale/voltage_v: give both voltage_v and "
                                         "current_a"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eol
