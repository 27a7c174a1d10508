// Issue 34's fault injection, CI-sized: tests/peers/fault_injection.py drives `eol station`
// against `eol fixture-sim` over Modbus TCP from outside (Python's socket, struct and sqlite3,
// no code of ours) and repeats every failure of the station itself: many and hostile PLC
// clients, SIGKILL and SIGSTOP in excitation, stalls with interlocks that come and go, fixture
// link glitches, deep and wide HTTP requests with slow clients, and a damaged store. The
// figures it prints are the ones deploy/OPERATIONS.md "Fault injection" states.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/support/child_process.h"

namespace eol::testing {
namespace {

TEST(FaultInjection, TheStationFailsSafeWhenItselfFailsOrIsAttacked) {
  TempDir dir;
  ChildProcess run(
      {"/usr/bin/python3", std::string(EOL_SOURCE_DIR) + "/tests/peers/fault_injection.py", "--eol",
       EOL_BINARY, "--recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json", "--runs",
       "2", "--out", dir / "work", "--json", dir / "figures.json"});
  const auto code = run.Wait(std::chrono::seconds(600));
  ASSERT_TRUE(code.has_value()) << "fault injection did not finish in 10 minutes\n" << run.output();
  std::ifstream in(dir / "figures.json");
  ASSERT_TRUE(in) << run.output();
  const nlohmann::json f = nlohmann::json::parse(in);
  EXPECT_TRUE(f["plc_clients"]["daemon_alive"].get<bool>()) << f.dump(2);
  for (const char* how : {"kill", "stop"}) {
    EXPECT_EQ(f[how]["relay_stuck_10s"], 0) << how << "\n" << f.dump(2);
    // The controller's alive timeout (250 ms) plus the observer's and the emulator's scan.
    EXPECT_LT(f[how]["relay_off_ms_max"].get<double>(), 400.0) << how << "\n" << f.dump(2);
  }
  for (const auto& [fault, v] : f["stall"].items()) EXPECT_EQ(v["pass"], 0) << fault;
  for (const auto& [mode, v] : f["glitch"].items()) EXPECT_EQ(v["pass"], 0) << mode;
  EXPECT_TRUE(f["http"]["daemon_alive"].get<bool>()) << f.dump(2);
  // Alone on the machine 0 of 100 fail; with the suite's fuzzers beside it on two cores one
  // was seen failing (the script records how in status_failed_kinds).
  EXPECT_LE(f["http"]["status_failed"].get<int>(), 2) << f.dump(2);
  EXPECT_TRUE(f["store"]["zeroed_page"]["refused"].get<bool>()) << f.dump(2);
  EXPECT_TRUE(f["store"]["empty_file"]["refused"].get<bool>()) << f.dump(2);
  EXPECT_TRUE(f["store"]["wal_deleted"]["missing_named_or_none"].get<bool>()) << f.dump(2);
  EXPECT_EQ(*code, 0) << run.output();
}

}  // namespace
}  // namespace eol::testing
