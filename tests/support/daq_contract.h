// The contract of drivers::Daq (drivers/daq/daq.h), one parameterised suite that every
// acquisition backend runs (tests/README.md): sim, replay and ALSA. Each backend is a DaqBackend
// that makes a DaqUnderTest: the driver configured with ContractCalibration() and ready for
// ContractRequest(), plus a second driver of the same backend whose device is broken, so
// that the suite can check that errors name the device. A backend that needs something the
// machine may not offer (a sound server) says why in unavailable(), and its tests are
// skipped with that reason.
//
// Include this header in one test program and instantiate it:
//   INSTANTIATE_TEST_SUITE_P(Backends, DaqContractTest, ::testing::Values(...), DaqBackendName);
#pragma once

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <string>
#include <thread>

#include "drivers/daq/daq.h"

namespace eol::testing {

// 48 kHz (the null sink's rate), two periods of 4800 samples of a 1 kHz sine at 0.3 V:
// 0.2 s of signal, periodic, well inside any line output's full scale.
inline drivers::AcquisitionRequest ContractRequest(std::size_t periods = 2) {
  drivers::AcquisitionRequest r;
  r.sample_rate_hz = 48000.0;
  r.period_samples = 4800;
  r.excitation_v.resize(periods * r.period_samples);
  for (std::size_t k = 0; k < r.excitation_v.size(); ++k)
    r.excitation_v[k] =
        0.3 * std::sin(2.0 * std::numbers::pi * 1000.0 * static_cast<double>(k) / 48000.0);
  return r;
}

// Distinct from every default, so that a backend that reports its own default is caught.
inline drivers::Calibration ContractCalibration() {
  drivers::Calibration c;
  c.shunt_ohm = 0.25;
  c.divider_ratio = 3.0;
  c.channel_delay_s = 2.0e-6;
  c.method = "reference_resistor";
  c.date = "2024-05-06T07:08:09Z";
  c.reference_ohm = 1.5;
  return c;
}

class DaqUnderTest {
 public:
  virtual ~DaqUnderTest() = default;
  // Empty when the backend can run here; else why not (the tests are skipped with it).
  virtual std::string unavailable() const { return ""; }
  virtual drivers::Daq& daq() = 0;
  // True when an acquisition takes the request's duration in real time, so that an abort
  // can arrive while it streams.
  virtual bool real_time() const = 0;
  // A driver of this backend whose device fails at Connect or at Acquire, and text that its
  // error must contain to name that device.
  virtual drivers::Daq& broken() = 0;
  virtual std::string broken_device() const = 0;
};

struct DaqBackend {
  std::string name;
  std::function<std::unique_ptr<DaqUnderTest>()> start;
};

inline std::string DaqBackendName(const ::testing::TestParamInfo<DaqBackend>& info) {
  return info.param.name;
}
inline void PrintTo(const DaqBackend& b, std::ostream* os) { *os << b.name; }

class DaqContractTest : public ::testing::TestWithParam<DaqBackend> {
 protected:
  using Lifecycle = drivers::Lifecycle;

  void SetUp() override {
    under_test_ = GetParam().start();
    ASSERT_NE(under_test_, nullptr);
    if (!under_test_->unavailable().empty()) GTEST_SKIP() << under_test_->unavailable();
  }
  void TearDown() override {
    if (under_test_ && under_test_->unavailable().empty()) under_test_->daq().Disconnect();
    under_test_.reset();
  }

  drivers::Daq& daq() { return under_test_->daq(); }
  std::string Prefix() const { return "daq '" + under_test_->daq().name() + "': "; }
  void Connect() {
    const drivers::Status s = daq().Connect();
    ASSERT_TRUE(s.ok()) << s.message();
  }

  std::unique_ptr<DaqUnderTest> under_test_;
};

TEST_P(DaqContractTest, LifecycleAndAcquireOnlyWhenConnected) {
  const std::atomic<bool> abort{false};
  EXPECT_EQ(daq().lifecycle(), Lifecycle::kUnconfigured);
  const auto early = daq().Acquire(ContractRequest(), abort);
  ASSERT_FALSE(early.ok());
  EXPECT_EQ(early.status().message(), Prefix() + "acquire: not connected (state unconfigured)");
  Connect();
  EXPECT_EQ(daq().lifecycle(), Lifecycle::kInactive);
  EXPECT_TRUE(daq().Connect().ok()) << "connecting twice";
  daq().Disconnect();
  EXPECT_EQ(daq().lifecycle(), Lifecycle::kFinalized);
  const auto late = daq().Acquire(ContractRequest(), abort);
  ASSERT_FALSE(late.ok());
  EXPECT_EQ(late.status().message(), Prefix() + "acquire: not connected (state finalized)");
}

TEST_P(DaqContractTest, AcquisitionHasTheRequestedSamplesAndRate) {
  Connect();
  const drivers::AcquisitionRequest req = ContractRequest();
  const std::atomic<bool> abort{false};
  for (int run = 0; run < 2; ++run) {  // a connection serves one acquisition after another
    const auto rec = daq().Acquire(req, abort);
    ASSERT_TRUE(rec.ok()) << "run " << run << ": " << rec.status().message();
    EXPECT_EQ(rec.value().voltage_v.size(), req.excitation_v.size());
    EXPECT_EQ(rec.value().current_a.size(), req.excitation_v.size());
    EXPECT_EQ(rec.value().sample_rate_hz, req.sample_rate_hz);
    EXPECT_EQ(rec.value().period_samples, req.period_samples);
    EXPECT_EQ(daq().lifecycle(), Lifecycle::kInactive);
  }
  const auto empty = daq().Acquire(drivers::AcquisitionRequest{}, abort);
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().message(), Prefix() + "acquire: empty excitation or no sample rate");
}

// An abort already raised returns at once; one raised while a real-time acquisition
// streams ends it long before the excitation would have. Either way the device stays usable.
TEST_P(DaqContractTest, AbortIsHonoured) {
  Connect();
  const std::atomic<bool> raised{true};
  const auto before = daq().Acquire(ContractRequest(), raised);
  ASSERT_FALSE(before.ok()) << "an acquisition ran through a raised abort";
  EXPECT_EQ(before.status().message(), Prefix() + "aborted: excitation stopped");
  EXPECT_EQ(daq().lifecycle(), Lifecycle::kInactive) << "an abort is no device error";

  if (under_test_->real_time()) {
    const drivers::AcquisitionRequest ten_s = ContractRequest(100);
    std::atomic<bool> abort{false};
    const auto t0 = std::chrono::steady_clock::now();
    std::thread stopper([&] {
      std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the stream is running
      abort = true;
    });
    const auto during = daq().Acquire(ten_s, abort);
    stopper.join();
    const double took_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    ASSERT_FALSE(during.ok()) << "a 10 s acquisition ignored its abort";
    EXPECT_EQ(during.status().message(), Prefix() + "aborted: excitation stopped");
    EXPECT_LT(took_s, 5.0) << "the abort was seen only after " << took_s << " s";
  }
  const std::atomic<bool> lowered{false};
  const auto after = daq().Acquire(ContractRequest(), lowered);
  EXPECT_TRUE(after.ok()) << after.status().message();
}

TEST_P(DaqContractTest, CalibrationIsReported) {
  const drivers::Calibration want = ContractCalibration();
  for (int connected = 0; connected < 2; ++connected) {
    const drivers::Calibration got = daq().calibration();
    EXPECT_EQ(got.shunt_ohm, want.shunt_ohm);
    EXPECT_EQ(got.divider_ratio, want.divider_ratio);
    EXPECT_EQ(got.channel_delay_s, want.channel_delay_s);
    EXPECT_EQ(got.method, want.method);
    EXPECT_EQ(got.date, want.date);
    EXPECT_EQ(got.reference_ohm, want.reference_ohm);
    if (!connected) Connect();
  }
}

TEST_P(DaqContractTest, ErrorsNameTheDevice) {
  drivers::Daq& bad = under_test_->broken();
  const std::atomic<bool> abort{false};
  drivers::Status s = bad.Connect();
  if (s.ok()) {
    const auto rec = bad.Acquire(ContractRequest(), abort);
    ASSERT_FALSE(rec.ok()) << "the broken device acquired";
    s = rec.status();
  }
  EXPECT_EQ(s.message().rfind("daq '" + bad.name() + "': ", 0), 0u) << s.message();
  EXPECT_NE(s.message().find(under_test_->broken_device()), std::string::npos)
      << "'" << under_test_->broken_device() << "' not named in: " << s.message();
  EXPECT_EQ(bad.lifecycle(), Lifecycle::kError);
  bad.Disconnect();
}

}  // namespace eol::testing
