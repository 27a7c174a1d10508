// The ALSA acquisition driver (drivers/daq/alsa_daq.h) in real time against a real sound
// server: PulseAudio with a null sink, started by the test as its own child process (own
// HOME, runtime dir and socket), reached through the "pulse" ALSA plugin (libasound2-plugins).
// Playback goes to the null sink, capture reads the sink's monitor, so what was played comes
// back on both input channels after the server's latency. Contracts: the played multisine
// comes back (delay found, correlation and amplitude sane); a stalled reader is reported as
// an xrun naming the device and the frame; an excitation beyond the output's full scale is
// refused before anything is played. Lifecycle, sample count, abort, calibration and errors
// naming the device are the DAQ contract's (tests/support/daq_contract.h, daq_contract_test).
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "analysis/signal/multisine.h"
#include "drivers/daq/alsa_daq.h"
#include "drivers/factory/daq_config.h"
#include "tests/support/pulse_server.h"

#if EOL_WITH_ALSA  // else the driver is not built: nothing to test
namespace eol::drivers {
namespace {

using eol::testing::PulseServer;

constexpr double kRateHz = 48000.0;

AlsaDaqSettings PulseSettings() {
  AlsaDaqSettings s;
  s.playback_device = "pulse:eol_null";
  s.capture_device = "pulse:eol_null.monitor";
  s.format = AlsaSampleFormat::kFloat;
  s.period_frames = 2048;  // 341 ms of buffer: no xrun from a loaded machine (ctest -j)
  s.buffer_periods = 8;
  s.output_v_per_fs = 1.0;
  s.voltage_v_per_fs = 2.0;        // 1 V at the input reads 2 V
  s.current_v_per_fs = 0.5;        // 1 V across the shunt ...
  s.calibration.shunt_ohm = 0.25;  // ... is 0.5 V / 0.25 ohm = 2 A
  return s;
}

analysis::Excitation Multisine() {
  analysis::MultisineOptions o;
  o.sample_rate_hz = kRateHz;
  o.line_spacing_hz = 10.0;  // 4800 samples a period
  o.f_lo_hz = 200.0;
  o.f_hi_hz = 2000.0;
  o.peak_v = 0.5;
  o.crest_iterations = 30;
  return analysis::DesignMultisine(o);
}

// The lag (samples) at which y best matches x: coarse by the onset of y, fine by the
// correlation around it. Returns the correlation coefficient and the amplitude ratio there.
struct Match {
  std::size_t lag = 0;
  double correlation = 0.0;
  double gain = 0.0;
};

// played[start..] (the multisine after leading silence) is looked for in `recorded` around
// the onset of the recorded signal; lag is the recorded index of played[start].
Match FindPlayed(const std::vector<double>& played, std::size_t start,
                 const std::vector<double>& recorded, std::size_t compare) {
  double peak = 0.0;
  for (double v : recorded) peak = std::max(peak, std::abs(v));
  std::size_t onset = 0;
  while (onset < recorded.size() && std::abs(recorded[onset]) < 0.2 * peak) ++onset;
  Match best;
  const std::size_t lo = onset > 400 ? onset - 400 : 0;
  for (std::size_t lag = lo; lag <= onset + 400 && lag + compare <= recorded.size(); ++lag) {
    double xy = 0, xx = 0, yy = 0;
    for (std::size_t k = 0; k < compare; ++k) {
      xy += played[start + k] * recorded[lag + k];
      xx += played[start + k] * played[start + k];
      yy += recorded[lag + k] * recorded[lag + k];
    }
    const double c = yy > 0.0 ? xy / std::sqrt(xx * yy) : 0.0;
    if (c > best.correlation) best = {lag, c, xy / xx};
  }
  return best;
}

TEST(AlsaPulse, PlayedMultisineComesBackOnBothChannels) {
  PulseServer server;
  if (!server.ready()) GTEST_SKIP() << server.why_not();
  AlsaDaq daq(PulseSettings());
  ASSERT_TRUE(daq.Connect().ok());
  const analysis::Excitation ex = Multisine();
  AcquisitionRequest req;
  req.sample_rate_hz = kRateHz;
  req.period_samples = ex.period_samples;
  // Silence longer than the playback buffer (the server may render that far ahead), then the
  // multisine: the onset marks the start. 5 + 10 periods, 1.5 s.
  const std::size_t silent_periods = 5;
  req.excitation_v.assign(silent_periods * ex.period_samples, 0.0);
  const std::vector<double> periods = ex.Repeat(10);
  req.excitation_v.insert(req.excitation_v.end(), periods.begin(), periods.end());
  const std::atomic<bool> abort{false};
  const auto result = daq.Acquire(req, abort);
  ASSERT_TRUE(result.ok()) << result.status().message();
  const analysis::Recording& rec = result.value();
  ASSERT_EQ(rec.voltage_v.size(), req.excitation_v.size());
  EXPECT_DOUBLE_EQ(rec.voltage_full_scale_v, 2.0);
  EXPECT_DOUBLE_EQ(rec.current_full_scale_a, 2.0);

  // Two periods of what was played, found after the server's latency in each channel.
  const std::size_t compare = 2 * ex.period_samples;
  const std::size_t start = silent_periods * ex.period_samples;
  const Match u = FindPlayed(req.excitation_v, start, rec.voltage_v, compare);
  const Match i = FindPlayed(req.excitation_v, start, rec.current_a, compare);
  const double delay_ms = 1e3 * (static_cast<double>(u.lag) - static_cast<double>(start)) / kRateHz;
  std::printf("pulse round trip: delay %.2f ms, correlation u %.6f i %.6f, gain u %.4f i %.4f\n",
              delay_ms, u.correlation, i.correlation, u.gain, i.gain);
  ASSERT_GT(u.correlation, 0.0) << "the played signal never came back";
  // The onset was recorded: before it the recording is the leading silence. (The lag itself
  // is the server's: the null sink renders ahead of real time, so its monitor may deliver the
  // signal earlier than its place in the playback stream, by up to the buffer.)
  ASSERT_GT(u.lag, 10u);
  double before = 0.0;
  for (std::size_t k = 0; k + 10 < u.lag; ++k)
    before = std::max(before, std::abs(rec.voltage_v[k]));
  EXPECT_LT(before, 1e-3) << "signal before the multisine's onset";
  EXPECT_GT(u.correlation, 0.999);
  EXPECT_GT(i.correlation, 0.999);
  EXPECT_EQ(u.lag, i.lag) << "the two capture channels are one stream: no skew between them";
  // Unity through the null sink: the voltage reads 2 V per volt played, the current 2 A.
  EXPECT_NEAR(u.gain, 2.0, 0.02);
  EXPECT_NEAR(i.gain, 2.0, 0.02);

  // The station acquires once per test on one connection: a second run is as good.
  const auto again = daq.Acquire(req, abort);
  ASSERT_TRUE(again.ok()) << again.status().message();
  const Match u2 = FindPlayed(req.excitation_v, start, again.value().voltage_v, compare);
  EXPECT_GT(u2.correlation, 0.999);
  EXPECT_NEAR(u2.gain, 2.0, 0.02);
  daq.Disconnect();
}

TEST(AlsaPulse, StalledReaderIsReportedAsXrun) {
  PulseServer server;
  if (!server.ready()) GTEST_SKIP() << server.why_not();
  AlsaDaqSettings s = PulseSettings();
  s.stall_after_frames = 9600;  // 0.2 s in, the reader sleeps for 2 s (buffer: 341 ms)
  s.stall_s = 2.0;
  AlsaDaq daq(s);
  ASSERT_TRUE(daq.Connect().ok());
  const analysis::Excitation ex = Multisine();
  AcquisitionRequest req;
  req.sample_rate_hz = kRateHz;
  req.period_samples = ex.period_samples;
  req.excitation_v = ex.Repeat(10);
  const std::atomic<bool> abort{false};
  const auto result = daq.Acquire(req, abort);
  ASSERT_FALSE(result.ok()) << "a 2 s stall against a 341 ms buffer must not give a result";
  const std::string& m = result.status().message();
  EXPECT_NE(m.find("xrun"), std::string::npos) << m;
  EXPECT_NE(m.find("'pulse:eol_null"), std::string::npos) << m;  // names the device
  EXPECT_NE(m.find("at frame "), std::string::npos) << m;
  EXPECT_NE(m.find("of 48000 frames"), std::string::npos) << m;
  std::printf("%s\n", m.c_str());
  // The driver is in the error state until connected again.
  EXPECT_EQ(daq.lifecycle(), Lifecycle::kError);
}

TEST(AlsaPulse, ExcitationBeyondFullScaleIsRefusedBeforePlaying) {
  PulseServer server;
  if (!server.ready()) GTEST_SKIP() << server.why_not();
  AlsaDaqSettings s = PulseSettings();
  s.output_v_per_fs = 0.4;  // the multisine peaks at 0.5 V
  AlsaDaq daq(s);
  ASSERT_TRUE(daq.Connect().ok());
  const analysis::Excitation ex = Multisine();
  AcquisitionRequest req;
  req.sample_rate_hz = kRateHz;
  req.period_samples = ex.period_samples;
  req.excitation_v = ex.Repeat(2);
  const std::atomic<bool> abort{false};
  const auto result = daq.Acquire(req, abort);
  ASSERT_FALSE(result.ok());
  EXPECT_NE(result.status().message().find("exceeds the line output's full scale 0.4"),
            std::string::npos)
      << result.status().message();
}

TEST(AlsaConfig, ParsesGainsCalibrationAndNamesBadFields) {
  const nlohmann::json j = nlohmann::json::parse(R"({"driver": "alsa", "playback": "hw:1",
      "capture": "hw:1,0", "format": "S16_LE", "period_frames": 256,
      "gains": {"output_v_per_fs": 2.5, "voltage_v_per_fs": 10, "current_v_per_fs": 1},
      "calibration": {"shunt_ohm": 0.05, "divider_ratio": 20, "channel_delay_s": 1e-5}})");
  io::JsonObject o(j, "/daq");
  (void)o.RequiredString("driver");
  const AlsaDaqSettings s = ParseAlsaDaqSettings(o);
  EXPECT_EQ(s.playback_device, "hw:1");
  EXPECT_EQ(s.capture_device, "hw:1,0");
  EXPECT_EQ(s.format, AlsaSampleFormat::kS16);
  EXPECT_EQ(s.period_frames, 256u);
  EXPECT_DOUBLE_EQ(s.output_v_per_fs, 2.5);
  EXPECT_DOUBLE_EQ(s.calibration.shunt_ohm, 0.05);
  EXPECT_DOUBLE_EQ(s.calibration.divider_ratio, 20.0);
  EXPECT_DOUBLE_EQ(s.calibration.channel_delay_s, 1e-5);

  nlohmann::json bad = j;
  bad["format"] = "S24_3LE";
  io::JsonObject ob(bad, "/daq");
  (void)ob.RequiredString("driver");
  try {
    ParseAlsaDaqSettings(ob);
    FAIL() << "S24_3LE accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/daq/format"), std::string::npos) << e.what();
  }
  bad = j;
  bad["gains"]["current_v_per_fs"] = 0;
  io::JsonObject og(bad, "/daq");
  (void)og.RequiredString("driver");
  try {
    ParseAlsaDaqSettings(og);
    FAIL() << "zero gain accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/daq/gains/current_v_per_fs"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eol::drivers
#endif  // EOL_WITH_ALSA
