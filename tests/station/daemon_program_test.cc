// The daemon's own program, build/eol-station (what deploy/eol-station.service runs): the
// options of `eol station` from the same parser, the same exit codes, hardware drivers only
// (a config naming a simulated driver is refused naming where the simulators are), and a
// test from a serial to a stored record with the fixture over Modbus TCP (`eol fixture-sim`)
// and the acquisition replayed from a recording (`eol simulate`). Its symbols are checked by
// tests/tools/daemon_symbols.sh (ctest daemon_program_symbols).
#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <string>
#include <thread>

#include "db/store.h"
#include "tests/support/child_process.h"
#include "tests/support/station_ready.h"

namespace eol {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::PortFromReadyLine;
using eol::testing::TempDir;

const std::string kDaemon = (fs::path(EOL_BINARY).parent_path() / "eol-station").string();

struct ProgramRun {
  int code = -1;
  std::string out;
};

ProgramRun Start(std::vector<std::string> args) {
  ChildProcess p(args, /*merge_stderr=*/true);
  return {p.Wait(60s).value_or(-1), p.output()};
}

// The options a help text lists ("--config", "-h,--help", ...), without help and version.
std::set<std::string> Options(const std::string& help) {
  std::set<std::string> out;
  std::istringstream in(help);
  std::string line;
  while (std::getline(in, line)) {
    const auto at = line.find_first_not_of(' ');
    if (at == 0 || at == std::string::npos || line[at] != '-') continue;
    const std::string name = line.substr(at, line.find(' ', at) - at);
    if (name != "-h,--help" && name != "--version") out.insert(name);
  }
  return out;
}

// The line of an output that holds `key`.
std::string LineWith(const std::string& out, const std::string& key) {
  const auto at = out.find(key);
  if (at == std::string::npos) return "";
  const auto begin = out.rfind('\n', at);
  return out.substr(begin == std::string::npos ? 0 : begin + 1,
                    out.find('\n', at) - (begin == std::string::npos ? 0 : begin + 1));
}

nlohmann::json Config(const TempDir& dir, const std::string& fixture_driver) {
  return {{"station_id", "daemon-1"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "eol.sqlite"},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", fixture_driver}}},
          {"daq", {{"driver", "replay"}, {"file", dir / "rec.csv"}, {"repeat", true}}}};
}

TEST(DaemonProgram, HasTheOptionsOfEolStation) {
  const ProgramRun daemon = Start({kDaemon, "--help"});
  const ProgramRun alias = Start({EOL_BINARY, "station", "--help"});
  ASSERT_EQ(daemon.code, 0) << daemon.out;
  ASSERT_EQ(alias.code, 0) << alias.out;
  const std::set<std::string> want = {"--config", "--web-root", "--init-store"};
  EXPECT_EQ(Options(daemon.out), want) << daemon.out;
  EXPECT_EQ(Options(alias.out), want) << alias.out;
  EXPECT_EQ(Start({kDaemon}).code, 2);  // --config is required, as for `eol station`
  const ProgramRun version = Start({kDaemon, "--version"});
  EXPECT_EQ(version.code, 0);
  EXPECT_EQ(version.out, Start({EOL_BINARY, "--version"}).out);
}

TEST(DaemonProgram, AConfigErrorIsExit78AsForEolStation) {
  TempDir dir;
  nlohmann::json config = Config(dir, "modbus-tcp");
  config["recipe"] = dir / "missing.json";
  std::ofstream(dir / "station.json") << config.dump();
  const ProgramRun daemon = Start({kDaemon, "--config", dir / "station.json"});
  const ProgramRun alias = Start({EOL_BINARY, "station", "--config", dir / "station.json"});
  EXPECT_EQ(daemon.code, 78) << daemon.out;
  EXPECT_EQ(alias.code, 78) << alias.out;
  const std::string error = LineWith(daemon.out, "eol station: configuration error: ");
  EXPECT_NE(error.find("missing.json"), std::string::npos) << daemon.out;
  EXPECT_EQ(error, LineWith(alias.out, "eol station: configuration error: ")) << alias.out;
}

TEST(DaemonProgram, RefusesASimulatedDriverNamingWhereTheSimulatorsAre) {
  TempDir dir;
  std::ofstream(dir / "station.json") << Config(dir, "sim").dump();
  const ProgramRun daemon = Start({kDaemon, "--config", dir / "station.json"});
  EXPECT_EQ(daemon.code, 78) << daemon.out;
  EXPECT_NE(daemon.out.find("/fixture/driver: the sim driver is not in this program"),
            std::string::npos)
      << daemon.out;
}

TEST(DaemonProgram, TestsAUnitOverModbusWithAReplayedRecording) {
  TempDir dir;
  ChildProcess simulate({EOL_BINARY, "simulate", "--motor",
                         std::string(EOL_SOURCE_DIR) + "/recipes/motors/pmsm-10pole.json",
                         "--format", "recording", "--model", "steady_state", "--seed", "1", "--out",
                         dir / "rec.csv"});
  ASSERT_EQ(simulate.Wait(120s).value_or(-1), 0) << simulate.output();
  ChildProcess fixture({EOL_BINARY, "fixture-sim", "--port", "0", "--ready-file",
                        dir / "fixture.port", "--part", "HW-0001"});
  ASSERT_TRUE(
      fixture.WaitFor([&](const std::string&) { return fs::exists(dir / "fixture.port"); }, 30s))
      << fixture.output();
  int fixture_port = 0;
  std::ifstream(dir / "fixture.port") >> fixture_port;
  ASSERT_GT(fixture_port, 0);
  nlohmann::json config = Config(dir, "modbus-tcp");
  config["fixture"] = {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", fixture_port}};
  std::ofstream(dir / "station.json") << config.dump();

  ChildProcess daemon({kDaemon, "--config", dir / "station.json"});
  ASSERT_TRUE(daemon.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << daemon.output();
  httplib::Client http("127.0.0.1", PortFromReadyLine(daemon.output()));
  http.set_read_timeout(10, 0);
  const auto started = http.Post("/api/tests", R"({"serial": "HW-0001"})", "application/json");
  ASSERT_TRUE(started && started->status == 202) << (started ? started->body : "no answer");
  nlohmann::json test;
  const auto deadline = std::chrono::steady_clock::now() + 60s;
  while (test.is_null() && std::chrono::steady_clock::now() < deadline) {
    const auto res = http.Get("/api/units/HW-0001");
    if (res && res->status == 200) {
      const auto unit = nlohmann::json::parse(res->body);
      if (!unit["tests"].empty() && !unit["tests"][0]["finished_at"].get<std::string>().empty())
        test = unit["tests"][0];
    }
    if (test.is_null()) std::this_thread::sleep_for(50ms);
  }
  ASSERT_FALSE(test.is_null()) << daemon.output();
  EXPECT_EQ(test["outcome"], "PASS") << test["reasons"].dump();
  auto store = db::Store::Open(dir / "eol.sqlite", db::Store::Role::kReader);
  ASSERT_EQ(store->TestsOfSerial("HW-0001").size(), 1u);
}

}  // namespace
}  // namespace eol
