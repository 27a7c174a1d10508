// The acquisition contract (tests/support/daq_contract.h) run against the sim DAQ (in real
// time, so that an abort lands mid-stream), the replay DAQ (a WAV recording this test writes)
// and the ALSA DAQ against a PulseAudio null sink started by the test (skipped, naming why,
// when the build has no ALSA or no sound server can be started).
#include "tests/support/daq_contract.h"

#include <chrono>
#include <memory>
#include <stdexcept>
#include <string>

#include "drivers/daq/replay_daq.h"
#include "drivers/io/recording_files.h"
#include "drivers/sim/sim_clock.h"
#include "drivers/sim/sim_daq.h"
#include "tests/support/child_process.h"
#include "tests/support/pulse_server.h"
#if EOL_WITH_ALSA
#include "drivers/daq/alsa_daq.h"
#endif

namespace eol::testing {
namespace {

using drivers::SimBench;

class SimDaqUnderTest final : public DaqUnderTest {
 public:
  SimDaqUnderTest() {
    drivers::SimDaqSettings s;
    s.time_scale = 1.0;  // real time: an abort can arrive while it streams
    s.calibration = ContractCalibration();
    auto bench =
        std::make_shared<SimBench>(drivers::SimBenchSettings{}, drivers::ManualClock::Of(clock_));
    bench->LoadPart("CONTRACT-DAQ-1");
    bench->WriteAlive(1);  // the controller closes the relay only after a station_alive
    bench->Write(drivers::FixtureOutput::kExcitationEnable, true);
    daq_ = std::make_unique<drivers::SimDaq>(bench, s);
    // The broken one: its bench's acquisition device fails from the first chunk on.
    auto failing =
        std::make_shared<SimBench>(drivers::SimBenchSettings{}, drivers::ManualClock::Of(clock_));
    failing->InjectFault(drivers::SimFault::kDaqFails, std::chrono::milliseconds(0), false);
    broken_ = std::make_unique<drivers::SimDaq>(failing, s);
  }
  drivers::Daq& daq() override { return *daq_; }
  bool real_time() const override { return true; }
  drivers::Daq& broken() override { return *broken_; }
  std::string broken_device() const override {
    return "acquire: input overrun at sample 0 (simulated: daq_fails)";
  }

 private:
  std::shared_ptr<drivers::ManualClock> clock_ = std::make_shared<drivers::ManualClock>();
  std::unique_ptr<drivers::SimDaq> daq_, broken_;
};

class ReplayDaqUnderTest final : public DaqUnderTest {
 public:
  ReplayDaqUnderTest() {
    const drivers::AcquisitionRequest req = ContractRequest();
    analysis::Recording rec;
    rec.sample_rate_hz = req.sample_rate_hz;
    rec.voltage_v = req.excitation_v;
    rec.current_a.resize(req.excitation_v.size());
    for (std::size_t k = 0; k < rec.current_a.size(); ++k)
      rec.current_a[k] = 0.5 * req.excitation_v[k];
    const std::string wav = dir_ / "run-1.wav";
    io::WriteWavRecording(wav, rec, 1.0, 1.0);
    drivers::ReplayDaqSettings s;
    s.files = {wav};
    s.repeat = true;
    s.calibration = ContractCalibration();
    daq_ = std::make_unique<drivers::ReplayDaq>(s);
    s.files = {missing_};
    broken_ = std::make_unique<drivers::ReplayDaq>(s);
  }
  drivers::Daq& daq() override { return *daq_; }
  bool real_time() const override { return false; }
  drivers::Daq& broken() override { return *broken_; }
  std::string broken_device() const override { return "recording " + missing_ + ": no such file"; }

 private:
  TempDir dir_;
  const std::string missing_ = dir_ / "missing.wav";
  std::unique_ptr<drivers::ReplayDaq> daq_, broken_;
};

#if EOL_WITH_ALSA
class AlsaDaqUnderTest final : public DaqUnderTest {
 public:
  AlsaDaqUnderTest() {
    if (!server_.ready()) return;
    drivers::AlsaDaqSettings s;
    s.playback_device = "pulse:eol_null";
    s.capture_device = "pulse:eol_null.monitor";
    s.format = drivers::AlsaSampleFormat::kFloat;
    s.period_frames = 2048;  // 341 ms of buffer: no xrun from a loaded machine
    s.buffer_periods = 8;
    s.calibration = ContractCalibration();
    daq_ = std::make_unique<drivers::AlsaDaq>(s);
    s.playback_device = s.capture_device = kMissing;
    broken_ = std::make_unique<drivers::AlsaDaq>(s);
  }
  std::string unavailable() const override {
    return server_.ready() ? "" : "no sound server for the ALSA backend: " + server_.why_not();
  }
  drivers::Daq& daq() override { return *daq_; }
  bool real_time() const override { return true; }
  drivers::Daq& broken() override { return *broken_; }
  std::string broken_device() const override {
    return "cannot open on playback '" + std::string(kMissing) + "': ";
  }

 private:
  static constexpr const char* kMissing = "hw:CARD=EolNoSuchCard";
  PulseServer server_;
  std::unique_ptr<drivers::AlsaDaq> daq_, broken_;
};
#else
class AlsaDaqUnderTest final : public DaqUnderTest {
 public:
  std::string unavailable() const override {
    return "built without ALSA (EOL_WITH_ALSA off): the alsa driver does not exist";
  }
  drivers::Daq& daq() override { throw std::logic_error("no ALSA"); }
  bool real_time() const override { return true; }
  drivers::Daq& broken() override { throw std::logic_error("no ALSA"); }
  std::string broken_device() const override { return ""; }
};
#endif

template <typename T>
DaqBackend Backend(const char* name) {
  return DaqBackend{name, [] { return std::unique_ptr<DaqUnderTest>(new T()); }};
}

INSTANTIATE_TEST_SUITE_P(Backends, DaqContractTest,
                         ::testing::Values(Backend<SimDaqUnderTest>("Sim"),
                                           Backend<ReplayDaqUnderTest>("Replay"),
                                           Backend<AlsaDaqUnderTest>("Alsa")),
                         DaqBackendName);

}  // namespace
}  // namespace eol::testing
