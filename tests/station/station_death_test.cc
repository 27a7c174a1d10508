// The station dying in excitation: `eol station` in its own process on `eol
// fixture-sim` over Modbus TCP. Killed (SIGKILL) or frozen (SIGSTOP) while the relay is
// closed, it sends nothing more, and the fixture controller opens the relay by itself within
// its alive timeout (250 ms after the last station_alive), as a third Modbus client reading
// the excitation coil sees, with no restart of the daemon. A frozen daemon that resumes ends
// the test ERROR "watchdog stalled", never PASS.
#include <gtest/gtest.h>
#include <httplib.h>
#include <modbus/modbus.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "tests/support/child_process.h"
#include "tests/support/station_ready.h"
#include "tests/support/stored_test.h"
#include "tests/support/wait_until.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using eol::testing::ChildProcess;
using eol::testing::PortFromReadyLine;
using eol::testing::TempDir;

// Coil 1 of the default map (excitation_enable) through a client of its own; -1 on failure.
int ReadExcitationCoil(modbus_t* ctx) {
  std::uint8_t bit = 2;
  return modbus_read_bits(ctx, 1, 1, &bit) == 1 ? bit : -1;
}

// Holding register 1 of the default map (station_alive); -1 on failure.
int ReadAlive(modbus_t* ctx) {
  std::uint16_t value = 0;
  return modbus_read_registers(ctx, 1, 1, &value) == 1 ? value : -1;
}

class StationDeath : public ::testing::Test {
 protected:
  void SetUp() override {
    fixture_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{EOL_BINARY, "fixture-sim", "--port", "0", "--ready-file",
                                 dir_ / "fixture.port", "--part", "ROTOR-ON-FIXTURE"});
    ASSERT_TRUE(fixture_->WaitFor(
        [&](const std::string&) { return std::filesystem::exists(dir_ / "fixture.port"); }, 30s))
        << fixture_->output();
    std::ifstream(dir_ / "fixture.port") >> fixture_port_;
    ASSERT_GT(fixture_port_, 0);
    std::ofstream(dir_ / "station.json") << nlohmann::json{
        {"station_id", "death"},
        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
        {"db", dir_ / "station.sqlite"},
        {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
        {"fixture", {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", fixture_port_}}},
        {"daq", {{"driver", "sim"}, {"time_scale", 1.0}, {"relay", "external"}}},
        {"sim",
         {{"clamp_close_s", 0.1},
          {"clamp_open_s", 0.05}}}}.dump();
    station_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{EOL_BINARY, "station", "--config", dir_ / "station.json"});
    ASSERT_TRUE(
        station_->WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
        << station_->output();
    http_ = std::make_unique<httplib::Client>("127.0.0.1", PortFromReadyLine(station_->output()));
    observer_ = modbus_new_tcp("127.0.0.1", fixture_port_);
    ASSERT_NE(observer_, nullptr);
    modbus_set_slave(observer_, 1);
    ASSERT_EQ(modbus_connect(observer_), 0);
  }
  void TearDown() override {
    if (observer_ != nullptr) {
      modbus_close(observer_);
      modbus_free(observer_);
    }
  }

  // Starts a test and returns once the observer reads the relay closed and the station's
  // watchdog keeping it closed: station_alive changed three times since (about 150 ms).
  void StartAndWaitForExcitation(const std::string& serial) {
    const auto started =
        http_->Post("/api/tests", nlohmann::json{{"serial", serial}}.dump(), "application/json");
    ASSERT_TRUE(started && started->status == 202) << (started ? started->body : "no answer");
    ASSERT_TRUE(eol::testing::WaitUntil([&] { return ReadExcitationCoil(observer_) == 1; },
                                        eol::testing::kGenerousDeadline, 2ms))
        << "the relay never closed\n"
        << station_->output();
    int changes = 0;
    int last = ReadAlive(observer_);
    ASSERT_TRUE(eol::testing::WaitUntil(
        [&] {
          const int now = ReadAlive(observer_);
          if (now >= 0 && now != last) ++changes;
          last = now;
          return changes >= 3;
        },
        eol::testing::kGenerousDeadline, 5ms))
        << "station_alive stood still in excitation\n"
        << station_->output();
    ASSERT_EQ(ReadExcitationCoil(observer_), 1);
  }

  // Ms from `since` until the observer reads the relay open; -1 after 5 s.
  double RelayOffAfter(Clock::time_point since) {
    while (ReadExcitationCoil(observer_) != 0) {
      if (Clock::now() - since > 5s) return -1;
      std::this_thread::sleep_for(1ms);
    }
    return std::chrono::duration<double, std::milli>(Clock::now() - since).count();
  }

  TempDir dir_;
  int fixture_port_ = 0;
  std::unique_ptr<ChildProcess> fixture_, station_;
  std::unique_ptr<httplib::Client> http_;
  modbus_t* observer_ = nullptr;
};

TEST_F(StationDeath, KilledInExcitationTheRelayOpensWithinTheAliveTimeout) {
  StartAndWaitForExcitation("KILL-1");
  const auto t0 = Clock::now();
  kill(station_->pid(), SIGKILL);
  const double off_ms = RelayOffAfter(t0);
  std::printf("relay open %.1f ms after SIGKILL\n", off_ms);
  EXPECT_GE(off_ms, 0.0) << "the relay stayed closed 5 s after the station died";
  EXPECT_LE(off_ms, 300.0) << "alive timeout 250 ms, then the observer's poll";
}

TEST_F(StationDeath, FrozenInExcitationTheRelayOpensAndTheResumedTestIsErrorStalled) {
  StartAndWaitForExcitation("STOP-1");
  const auto t0 = Clock::now();
  kill(station_->pid(), SIGSTOP);
  const double off_ms = RelayOffAfter(t0);
  std::this_thread::sleep_until(t0 + 1500ms);
  kill(station_->pid(), SIGCONT);
  std::printf("relay open %.1f ms after SIGSTOP\n", off_ms);
  EXPECT_GE(off_ms, 0.0) << "the relay stayed closed through the freeze";
  EXPECT_LE(off_ms, 300.0);

  const nlohmann::json test =
      eol::testing::WaitForStoredTest(*http_, "STOP-1", eol::testing::kGenerousDeadline);
  ASSERT_FALSE(test.is_null()) << station_->output();
  EXPECT_EQ(test["outcome"], "ERROR") << test.dump();
  EXPECT_NE(test["reasons"].dump().find("watchdog stalled"), std::string::npos) << test.dump();
  EXPECT_GE(test["conditions"].value("watchdog_max_gap_ms", 0.0), 1400.0) << test.dump();
  EXPECT_FALSE(station_->Wait(0ms).has_value()) << "the daemon must live on";
}

}  // namespace
}  // namespace eol
