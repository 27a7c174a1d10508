// Crash safety: the daemon is killed with SIGKILL at random moments of a test, many times.
// After every kill the database must open consistent, no unfinished test may ever read as
// PASS, and the next start must record the interrupted test as ABORTED.
#include <gtest/gtest.h>
#include <httplib.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>

#include "../support/child_process.h"
#include "../support/station_ready.h"
#include "db/store.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

using eol::testing::PortFromReadyLine;

TEST(KillAtRandom, DatabaseStaysConsistentAndInterruptedTestsBecomeAborted) {
  eol::testing::TempDir dir;
  const std::string db_path = dir / "station.sqlite";
  std::ofstream(dir / "station.json")
      << nlohmann::json{{"station_id", "crash"},
                        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
                        {"db", db_path},
                        {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
                        {"fixture", {{"driver", "sim"}}},
                        {"daq", {{"driver", "sim"}, {"time_scale", 0.1}}},
                        {"sim", {{"clamp_close_s", 0.1}, {"clamp_open_s", 0.05}}}}
             .dump();

  std::mt19937 rng(20261122);
  std::uniform_int_distribution<int> kill_after_ms(0, 1400);
  constexpr int kCycles = 14;
  int running_at_kill = 0;
  bool expect_recovery_message = false;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
    ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
        << station.output();
    if (expect_recovery_message) {
      EXPECT_NE(station.output().find("recorded as ABORTED"), std::string::npos)
          << "cycle " << cycle << ": the interrupted test was not recovered at start";
    }
    httplib::Client http("127.0.0.1", PortFromReadyLine(station.output()));
    const std::string serial = "CRASH-" + std::to_string(cycle);
    const auto res =
        http.Post("/api/tests", nlohmann::json{{"serial", serial}}.dump(), "application/json");
    ASSERT_TRUE(res && res->status == 202) << (res ? res->body : "no answer");

    // While the test runs, readers never see it as a verdict, let alone a PASS.
    const auto kill_at =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kill_after_ms(rng));
    while (std::chrono::steady_clock::now() < kill_at) {
      const auto unit = http.Get(("/api/units/" + serial).c_str());
      if (unit && unit->status == 200) {
        for (const auto& t : nlohmann::json::parse(unit->body)["tests"])
          EXPECT_FALSE(t["finished_at"].get<std::string>().empty()) << t.dump();
      }
      std::this_thread::sleep_for(20ms);
    }
    ASSERT_TRUE(station.Stop(SIGKILL, 10s).has_value());

    auto reader = db::Store::Open(db_path, db::Store::Role::kReader);
    EXPECT_EQ(reader->IntegrityCheck(), "ok") << "cycle " << cycle;
    const int running = reader->CountRunning();
    EXPECT_LE(running, 1);
    running_at_kill += running;
    expect_recovery_message = running > 0;
    for (const auto& t : reader->TestsOfSerial(serial)) {
      EXPECT_FALSE(t.finished_at.empty());
      if (t.outcome == analysis::Outcome::kPass) {
        EXPECT_FALSE(t.measurements.empty());
        for (const auto& m : t.measurements)
          EXPECT_EQ(m.outcome, analysis::MeasurementOutcome::kPass);
      }
    }
  }

  // The next writer recovers the last interruption; afterwards nothing is left RUNNING.
  auto store = db::Store::Open(db_path);
  EXPECT_EQ(store->IntegrityCheck(), "ok");
  EXPECT_EQ(store->CountRunning(), 0);
  int aborted = 0, finished = 0;
  for (int cycle = 0; cycle < kCycles; ++cycle) {
    const auto tests = store->TestsOfSerial("CRASH-" + std::to_string(cycle));
    ASSERT_LE(tests.size(), 1u);
    if (tests.empty()) continue;  // killed before the test was begun
    if (tests.front().outcome == analysis::Outcome::kAborted) {
      ++aborted;
      EXPECT_EQ(tests.front().reasons.front(),
                (analysis::Reason{analysis::ReasonCode::kAborted,
                                  "interrupted: station stopped before the test finished"}));
    } else {
      ++finished;
    }
  }
  EXPECT_EQ(aborted, running_at_kill) << "every test running at a kill must end ABORTED";
  // The random kill points must have hit both inside and after tests, or the test proves little.
  EXPECT_GT(aborted, 0);
  EXPECT_GT(finished, 0);
}

}  // namespace
}  // namespace eol
