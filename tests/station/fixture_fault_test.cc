// Faults injected through `eol fixture-sim` over real Modbus TCP, against the station daemon
// (`eol station`) in its own process: each fault during excitation must end the test as ERROR
// with its cause in the stored record, never PASS; the excitation coil must be off at the
// fixture; and once the fixture is healthy again the next test runs to a verdict without a
// restart of the daemon.
#include <gtest/gtest.h>
#include <httplib.h>
#include <modbus/modbus.h>

#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>

#include "db/store.h"
#include "tests/support/child_process.h"
#include "tests/support/station_ready.h"
#include "tests/support/stored_test.h"
#include "tests/support/wait_until.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::TempDir;

struct FaultCase {
  std::string fault;
  std::string cause;  // a word the stored reason must contain
};

std::ostream& operator<<(std::ostream& os, const FaultCase& c) { return os << c.fault; }

using eol::testing::PortFromReadyLine;

int ReadPortFile(const std::string& path) {
  std::ifstream in(path);
  int port = 0;
  in >> port;
  return port;
}

// Coil 1 of the default map: excitation_enable, read by an independent client.
int ReadExcitationCoil(int port) {
  modbus_t* ctx = modbus_new_tcp("127.0.0.1", port);
  if (ctx == nullptr) return -1;
  modbus_set_slave(ctx, 1);
  std::uint8_t bit = 2;
  const int rc = modbus_connect(ctx) == 0 ? modbus_read_bits(ctx, 1, 1, &bit) : -1;
  modbus_close(ctx);
  modbus_free(ctx);
  return rc == 1 ? bit : -1;
}

// When a fault injected with --fault-on-excitation --fault-after-ms `after` and
// --fault-duration-ms `lasts` is over at the fixture, read from the stored record: the relay
// closed no earlier than the record's excite state, plus `margin` for the Modbus writes that
// close it. The epoch when the record has no excite state.
std::chrono::system_clock::time_point FaultOver(const db::TestRecord& r,
                                                std::chrono::milliseconds after,
                                                std::chrono::milliseconds lasts,
                                                std::chrono::milliseconds margin) {
  std::tm tm{};
  int ms = 0;
  std::istringstream in(r.started_at);
  in >> std::get_time(&tm, "%Y-%m-%dT%H:%M:%S");
  char dot = 0;
  in >> dot >> ms;
  if (in.fail()) return {};
  const auto started =
      std::chrono::system_clock::from_time_t(timegm(&tm)) + std::chrono::milliseconds(ms);
  for (const db::StateEntry& e : r.trace)
    if (e.state == "excite")
      return started + std::chrono::milliseconds(std::lround(e.t_ms)) + after + lasts + margin;
  return {};
}

class FixtureFault : public ::testing::TestWithParam<FaultCase> {};

TEST_P(FixtureFault, EndsInErrorWithTheCauseStoredAndTheStationRecovers) {
  const FaultCase& c = GetParam();
  TempDir dir;
  const std::string db_path = dir / "station.sqlite";
  const nlohmann::json sim = {{"clamp_close_s", 0.1}, {"clamp_open_s", 0.05}};
  // The fault shows 300 ms into the excitation (5 periods of 1 s played at 0.5 x real time)
  // and lasts 2.5 s: longer than the Modbus driver's retries and than the heartbeat timeout
  // (1 s: the controller's heartbeat moves at least every 500 ms), so every fault is seen
  // while the stator is excited.
  ChildProcess fixture({EOL_BINARY, "fixture-sim", "--port", "0", "--ready-file",
                        dir / "fixture.port", "--part", "ROTOR-ON-FIXTURE", "--fault", c.fault,
                        "--fault-on-excitation", "--fault-after-ms", "300", "--fault-duration-ms",
                        "2500"});
  ASSERT_TRUE(fixture.WaitFor(
      [&](const std::string&) { return std::filesystem::exists(dir / "fixture.port"); }, 30s))
      << fixture.output();
  const int fixture_port = ReadPortFile(dir / "fixture.port");
  ASSERT_GT(fixture_port, 0);

  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "faults"},
      // The shipped recipe's 5 s of excitation: the fault comes 300 ms into it.
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", db_path},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", fixture_port}}},
      {"daq", {{"driver", "sim"}, {"time_scale", 0.5}, {"relay", "external"}}},
      {"safety", {{"heartbeat_timeout_ms", 1000}}},
      {"sim", sim}}.dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  httplib::Client http("127.0.0.1", PortFromReadyLine(station.output()));

  const auto started =
      http.Post("/api/tests", nlohmann::json{{"serial", "FAULT-1"}}.dump(), "application/json");
  ASSERT_TRUE(started && started->status == 202) << (started ? started->body : "no answer");
  const nlohmann::json faulted = eol::testing::WaitForStoredTest(http, "FAULT-1", 60s);
  ASSERT_FALSE(faulted.is_null()) << station.output();
  EXPECT_EQ(faulted["outcome"], "ERROR") << faulted.dump();
  const std::string reasons = faulted["reasons"].dump();
  EXPECT_NE(reasons.find(c.cause), std::string::npos) << "reasons: " << reasons;

  // The stored record says the same; the daemon wrote it before it published the verdict.
  std::chrono::system_clock::time_point fault_over{};
  {
    auto reader = db::Store::Open(db_path, db::Store::Role::kReader);
    const auto tests = reader->TestsOfSerial("FAULT-1");
    ASSERT_EQ(tests.size(), 1u);
    EXPECT_EQ(tests.front().outcome, analysis::Outcome::kError);
    ASSERT_FALSE(tests.front().reasons.empty());
    EXPECT_NE(tests.front().reasons.front().text.find(c.cause), std::string::npos)
        << tests.front().reasons.front().text;
    fault_over = FaultOver(tests.front(), 300ms, 2500ms, 250ms);
  }

  // Excitation off at the fixture: read once the fixture answers again.
  int coil = -1;
  eol::testing::WaitUntil([&] { return (coil = ReadExcitationCoil(fixture_port)) >= 0; }, 10s,
                          100ms);
  EXPECT_EQ(coil, 0) << "excitation_enable must be off after the fault";

  // Recovery without a restart: once the fault is over at the fixture (as the record dates
  // it) and the station sees the fixture healthy again (ready), the next serial gets a verdict.
  ASSERT_NE(fault_over, std::chrono::system_clock::time_point{}) << "no excite state stored";
  ASSERT_TRUE(
      eol::testing::WaitUntil([&] { return std::chrono::system_clock::now() >= fault_over; }, 10s));
  ASSERT_TRUE(eol::testing::WaitUntil(
      [&] {
        const auto status = http.Get("/api/status");
        return status && status->status == 200 &&
               nlohmann::json::parse(status->body).value("ready", false);
      },
      30s, 50ms))
      << station.output();
  const auto again =
      http.Post("/api/tests", nlohmann::json{{"serial", "FAULT-2"}}.dump(), "application/json");
  ASSERT_TRUE(again && again->status == 202) << (again ? again->body : "no answer");
  const nlohmann::json recovered = eol::testing::WaitForStoredTest(http, "FAULT-2", 60s);
  ASSERT_FALSE(recovered.is_null()) << station.output();
  EXPECT_TRUE(recovered["outcome"] == "PASS" || recovered["outcome"] == "FAIL")
      << recovered.dump() << "\n"
      << station.output();
  EXPECT_FALSE(station.Wait(0ms).has_value()) << "the daemon must not need a restart";
}

INSTANTIATE_TEST_SUITE_P(
    EachFault, FixtureFault,
    ::testing::Values(FaultCase{"stops_answering", "fixture"}, FaultCase{"clamp_drops", "clamp"},
                      FaultCase{"pressure_low", "pressure"}, FaultCase{"door_opens", "door"},
                      FaultCase{"estop", "stop"}, FaultCase{"heartbeat_freezes", "heartbeat"}),
    [](const ::testing::TestParamInfo<FaultCase>& i) { return i.param.fault; });

}  // namespace
}  // namespace eol
