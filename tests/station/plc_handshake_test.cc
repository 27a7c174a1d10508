// The line PLC's handshake (station/daemon/plc/plc_map.h) against an independent PLC: Debian's
// pymodbus (tests/peers/pymodbus_plc_client.py) on 127.0.0.1, talking to a station that
// serves its queue in-process with the sim bench, a real SQLite file and the real PLC server
// on a free port. Each client run is one connection that ends when its operations do.
#include <gtest/gtest.h>

#include <chrono>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <regex>
#include <thread>

#include "db/store.h"
#include "drivers/io/json_config.h"
#include "station/daemon/plc/plc_map.h"
#include "station/daemon/station.h"
#include "tests/peers/modbus_peer_support.h"
#include "tests/support/child_process.h"
#include "tests/support/wait_until.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
namespace peers = eol::testing::modbus_peers;

class PlcHandshakeTest : public ::testing::Test {
 protected:
  void SetUp() override { ASSERT_TRUE(peers::PymodbusAvailable()); }
  void TearDown() override { StopStation(); }

  // GOOD-1.. are good rotors, SOFT-1 a soft magnet bond (the sim's masters, no self-checks).
  void StartStation(double clamp_close_s = 0.02, nlohmann::json map = nullptr) {
    nlohmann::json plc = {{"listen", "127.0.0.1"}, {"port", 0}, {"unit_id", 1}};
    if (!map.is_null()) plc["map"] = map;
    const nlohmann::json j = {{"station_id", "plc"},
                              {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
                              {"db", db_path_},
                              {"fixture", {{"driver", "sim"}}},
                              {"daq", {{"driver", "sim"}}},
                              {"sim",
                               {{"clamp_close_s", clamp_close_s},
                                {"clamp_open_s", 0.02},
                                {"population", {{"defect_share", 0.0}}},
                                {"masters",
                                 {{{"serial", "GOOD-1"}},
                                  {{"serial", "GOOD-2"}},
                                  {{"serial", "SOFT-1"}, {"defective", true}}}}}},
                              {"plc", plc}};
    station_ = std::make_unique<Station>(ParseStationConfig(j, "test", ""));
    station_->StartPlc();
    ASSERT_GT(station_->plc_port(), 0);
    serve_ = std::thread([this] { station_->Serve(); });
  }

  void StopStation() {
    if (!station_) return;
    station_->RequestStop("test over");
    if (serve_.joinable()) serve_.join();
    station_.reset();
  }

  // Runs the PLC's operations over one connection; asserts that every one was answered.
  nlohmann::json Plc(const nlohmann::json& ops) {
    std::string log;
    const nlohmann::json out = peers::RunPymodbusClientScript(
        "pymodbus_plc_client.py", {"--tcp", "127.0.0.1:" + std::to_string(station_->plc_port())},
        ops, &log, 300s);
    EXPECT_TRUE(out.is_array()) << log;
    if (!out.is_array()) return nlohmann::json::array();
    for (const auto& r : out) EXPECT_FALSE(r.contains("error")) << r.dump() << "\n" << log;
    return out;
  }

  // The PLC's half of a start: serial in, start set, wait until the station took it.
  static nlohmann::json StartOps(const std::string& serial) {
    return {{"write_text", 100, 16, serial}, {"write_coil", 100, 1}, {"wait_coil", 100, 0, 5}};
  }

  // Every stored record, newest first, from a reader connection of the test's own.
  std::vector<db::TestRecord> Stored() {
    auto store = db::Store::Open(db_path_, db::Store::Role::kReader);
    return store->Tests(db::TestQuery{});
  }

  eol::testing::TempDir dir_;
  const std::string db_path_ = dir_ / "plc.sqlite";
  std::unique_ptr<Station> station_;
  std::thread serve_;
};

TEST_F(PlcHandshakeTest, StartsTestsAndReadsPassAndFailWithTheCounter) {
  StartStation();
  // Idle: ready, nothing else; no result, counter 0, no refusal.
  nlohmann::json r = Plc({{"read_di", 100, 4}, {"read_ir", 100, 4}});
  EXPECT_EQ(r[0]["values"], nlohmann::json({0, 0, 1, 0}));
  EXPECT_EQ(r[1]["values"], nlohmann::json({0, 0, 0, 0}));

  nlohmann::json ops = StartOps("GOOD-1");
  ops.push_back({"read_ir", 103, 1});
  ops.push_back({"wait_di", 101, 1, 120});
  ops.push_back({"read_di", 100, 4});
  ops.push_back({"read_ir", 100, 4});
  r = Plc(ops);
  ASSERT_EQ(r.size(), 7u);
  // For station/README.md: how long the PLC waited for the station to take the start, and for done.
  std::cout << "[ figures  ] PLC start taken after " << r[2].value("waited_s", -1.0)
            << " s, done after " << r[4].value("waited_s", -1.0) << " s (sim test)\n";
  EXPECT_EQ(r[3]["values"], nlohmann::json::array({0})) << "refusal after an accepted start";
  EXPECT_EQ(r[5]["values"], nlohmann::json({0, 1, 1, 0})) << "busy, done, ready, lockout";
  EXPECT_EQ(r[6]["values"], nlohmann::json({1, 1, 0, 0})) << "PASS, counter 1, no reason";

  ops = StartOps("SOFT-1");
  ops.push_back({"read_di", 101, 1});  // done drops with the accepted start
  ops.push_back({"wait_di", 101, 1, 120});
  ops.push_back({"read_ir", 100, 4});
  r = Plc(ops);
  ASSERT_EQ(r.size(), 6u);
  EXPECT_EQ(r[3]["values"], nlohmann::json::array({0})) << "done must drop at the next start";
  const std::vector<db::TestRecord> stored = Stored();
  ASSERT_EQ(stored.size(), 2u);
  const db::TestRecord& soft = stored.front();
  ASSERT_EQ(soft.serial, "SOFT-1");
  ASSERT_EQ(soft.outcome, analysis::Outcome::kFail);
  ASSERT_FALSE(soft.reasons.empty());
  EXPECT_EQ(r[5]["values"],
            nlohmann::json({2, 2, plc::PlcReasonCode(soft.reasons.front().code), 0}))
      << "FAIL, counter 2, the first stored reason (" << soft.reasons.front().text << ")";
  EXPECT_EQ(stored.back().serial, "GOOD-1");
  EXPECT_EQ(stored.back().outcome, analysis::Outcome::kPass);
}

TEST_F(PlcHandshakeTest, ASecondStartWhileBusyIsRefusedAndStartsNothing) {
  StartStation(/*clamp_close_s=*/0.5);  // a test long enough to be busy for sure
  nlohmann::json ops = StartOps("GOOD-1");
  ops.push_back({"read_di", 100, 1});
  for (const auto& op : StartOps("GOOD-2")) ops.push_back(op);
  ops.push_back({"read_ir", 103, 1});
  ops.push_back({"read_di", 100, 3});
  ops.push_back({"wait_di", 101, 1, 120});
  ops.push_back({"read_ir", 100, 4});
  const nlohmann::json r = Plc(ops);
  ASSERT_EQ(r.size(), 11u);
  EXPECT_EQ(r[3]["values"], nlohmann::json::array({1})) << "busy after the first start";
  EXPECT_EQ(r[7]["values"], nlohmann::json::array({static_cast<int>(plc::PlcRefusal::kBusy)}));
  EXPECT_EQ(r[8]["values"], nlohmann::json({1, 0, 0})) << "still busy, not done, not ready";
  // The first test's result; the refusal stays readable until the next accepted start.
  EXPECT_EQ(r[10]["values"], nlohmann::json({1, 1, 0, 2}));
  const std::vector<db::TestRecord> stored = Stored();
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(stored.front().serial, "GOOD-1");
}

TEST_F(PlcHandshakeTest, ABadSerialIsRefusedWithItsCodeAndStartsNothing) {
  StartStation();
  const int bad = static_cast<int>(plc::PlcRefusal::kBadSerial);
  // "A", NUL, "B": a character after the end; then a bell; then nothing at all.
  nlohmann::json ops = {
      {"write_hrs", 100, {0x4100, 0x4200, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}},
      {"write_coil", 100, 1},
      {"wait_coil", 100, 0, 5},
      {"read_ir", 100, 4},
      {"write_hrs", 100, {0x4107, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0}},
      {"write_coil", 100, 1},
      {"wait_coil", 100, 0, 5},
      {"read_ir", 103, 1},
      {"write_text", 100, 16, ""},
      {"write_coil", 100, 1},
      {"wait_coil", 100, 0, 5},
      {"read_ir", 103, 1},
      {"read_di", 100, 4}};
  nlohmann::json r = Plc(ops);
  ASSERT_EQ(r.size(), 13u);
  EXPECT_EQ(r[3]["values"], nlohmann::json({0, 0, 0, bad}));
  EXPECT_EQ(r[7]["values"], nlohmann::json::array({bad}));
  EXPECT_EQ(r[11]["values"], nlohmann::json::array({bad}));
  EXPECT_EQ(r[12]["values"], nlohmann::json({0, 0, 1, 0})) << "idle and ready: nothing started";
  EXPECT_TRUE(Stored().empty());

  // A good serial after them is accepted and clears the refusal.
  ops = StartOps("GOOD-1");
  ops.push_back({"read_ir", 103, 1});
  ops.push_back({"wait_di", 101, 1, 120});
  r = Plc(ops);
  ASSERT_EQ(r.size(), 5u);
  EXPECT_EQ(r[3]["values"], nlohmann::json::array({0}));
  EXPECT_EQ(Stored().size(), 1u);
}

TEST_F(PlcHandshakeTest, APlcThatDisconnectsMidTestReadsTheStoredResultOnReconnecting) {
  StartStation(/*clamp_close_s=*/0.5);
  nlohmann::json ops = StartOps("GOOD-1");
  ops.push_back({"read_di", 100, 2});
  nlohmann::json r = Plc(ops);  // the connection closes here, the test still running
  ASSERT_EQ(r.size(), 4u);
  EXPECT_EQ(r[3]["values"], nlohmann::json({1, 0})) << "busy, not done, when the PLC left";

  eol::testing::WaitUntil([&] { return !Stored().empty(); }, 120s, 50ms);
  const std::vector<db::TestRecord> stored = Stored();
  ASSERT_EQ(stored.size(), 1u) << "the test must complete and be stored without its PLC";
  EXPECT_EQ(stored.front().outcome, analysis::Outcome::kPass);

  r = Plc({{"wait_di", 101, 1, 5}, {"read_di", 100, 4}, {"read_ir", 100, 4}});
  ASSERT_EQ(r.size(), 3u);
  EXPECT_EQ(r[1]["values"], nlohmann::json({0, 1, 1, 0}));
  EXPECT_EQ(r[2]["values"], nlohmann::json({1, 1, 0, 0}));
}

TEST_F(PlcHandshakeTest, OperatorShiftAndOrderBlocksAreStoredWithTheRecord) {
  StartStation();
  const int bad_field = static_cast<int>(plc::PlcRefusal::kBadField);
  // A shift with a control character is refused with its own code, nothing started.
  nlohmann::json ops = {{"write_text", 100, 16, "GOOD-1"},
                        {"write_hrs", 132, {0x4101, 0, 0, 0, 0, 0, 0, 0}},
                        {"write_coil", 100, 1},
                        {"wait_coil", 100, 0, 5},
                        {"read_ir", 103, 1},
                        {"write_text", 116, 16, "op-17"},
                        {"write_text", 132, 8, "night"},
                        {"write_text", 140, 16, "PO-4711/batch 3"},
                        {"write_coil", 100, 1},
                        {"wait_coil", 100, 0, 5},
                        {"read_ir", 103, 1},
                        {"wait_di", 101, 1, 120}};
  const nlohmann::json r = Plc(ops);
  ASSERT_EQ(r.size(), 12u);
  EXPECT_EQ(r[4]["values"], nlohmann::json::array({bad_field}));
  EXPECT_EQ(r[10]["values"], nlohmann::json::array({0}));
  const std::vector<db::TestRecord> stored = Stored();
  ASSERT_EQ(stored.size(), 1u);
  EXPECT_EQ(stored[0].work, (db::WorkContext{"op-17", "night", "PO-4711/batch 3"}));
}

TEST_F(PlcHandshakeTest, AMovedMapServesTheSameHandshakeAtTheNewAddresses) {
  StartStation(0.02, {{"serial", 0},
                      {"operator_id", 16},
                      {"shift", 32},
                      {"order_number", 40},
                      {"start", 7},
                      {"busy", 10},
                      {"done", 11},
                      {"ready", 12},
                      {"lockout", 13},
                      {"result", 20},
                      {"counter", 21},
                      {"reason", 22},
                      {"refusal", 23}});
  const nlohmann::json r = Plc({{"write_text", 0, 16, "GOOD-1"},
                                {"write_coil", 7, 1},
                                {"wait_coil", 7, 0, 5},
                                {"wait_di", 11, 1, 120},
                                {"read_ir", 20, 4},
                                {"read_ir", 100, 1}});
  ASSERT_EQ(r.size(), 6u);
  EXPECT_EQ(r[4]["values"], nlohmann::json({1, 1, 0, 0}));
  EXPECT_EQ(r[5].value("exception_code", 0), 2) << "the default address is not served";
}

// The daemon serves the PLC beside HTTP and announces the port on its ready line.
TEST(PlcDaemon, EolStationServesThePlcBesideHttp) {
  ASSERT_TRUE(peers::PymodbusAvailable());
  eol::testing::TempDir dir;
  std::ofstream(dir / "station.json")
      << nlohmann::json{{"station_id", "plc-d"},
                        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
                        {"db", dir / "d.sqlite"},
                        {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
                        {"fixture", {{"driver", "sim"}}},
                        {"daq", {{"driver", "sim"}}},
                        {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}},
                        {"plc", {{"listen", "127.0.0.1"}, {"port", 0}}}}
             .dump();
  eol::testing::ChildProcess daemon({EOL_BINARY, "station", "--config", dir / "station.json"});
  const std::regex ready("ready, .*, plc modbus://127\\.0\\.0\\.1:([0-9]+)");
  std::smatch m;
  ASSERT_TRUE(
      daemon.WaitFor([&](const std::string& out) { return std::regex_search(out, m, ready); }, 30s))
      << daemon.output();
  const std::string out = daemon.output();
  ASSERT_TRUE(std::regex_search(out, m, ready));
  std::string log;
  const nlohmann::json r =
      peers::RunPymodbusClientScript("pymodbus_plc_client.py", {"--tcp", "127.0.0.1:" + m[1].str()},
                                     {{"write_text", 100, 16, "GOOD-1"},
                                      {"write_coil", 100, 1},
                                      {"wait_coil", 100, 0, 5},
                                      {"wait_di", 101, 1, 120},
                                      {"read_ir", 100, 2}},
                                     &log, 300s);
  ASSERT_TRUE(r.is_array()) << log;
  ASSERT_EQ(r.size(), 5u) << log;
  EXPECT_EQ(r[4]["values"].size(), 2u) << log;
  EXPECT_NE(r[4]["values"][0], 0) << "a result" << log;
  EXPECT_EQ(r[4]["values"][1], 1) << "one stored" << log;
  EXPECT_EQ(daemon.Stop(SIGTERM, 30s), 0) << daemon.output();
}

TEST(PlcMap, OverridesAreCheckedNamingTheJsonPath) {
  const plc::PlcMap moved = plc::ParsePlcMap({{"serial", 200}, {"busy", 5}}, "/plc/map");
  EXPECT_EQ(moved.serial, 200);
  EXPECT_EQ(moved.busy, 5);
  EXPECT_EQ(moved.done, 101);
  auto message = [](const nlohmann::json& j) {
    try {
      plc::ParsePlcMap(j, "/plc/map");
    } catch (const io::ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_EQ(message({{"strat", 1}}).rfind("/plc/map/strat: unknown PLC signal (known: serial,", 0),
            0u)
      << message({{"strat", 1}});
  EXPECT_EQ(message({{"busy", 101}}), "/plc/map: busy and done share discrete input address 101");
  EXPECT_EQ(message({{"serial", 110}}),
            "/plc/map: serial and operator_id share holding register address 116");
  EXPECT_EQ(message({{"serial", 65530}}),
            "/plc/map: serial: holding register address 65530 (16 registers) is outside 0..65535");
  EXPECT_EQ(message({{"result", "100"}}),
            "/plc/map/result: must be an integer address (got \"100\")");
}

TEST(PlcMap, TextIsTwoCharactersPerRegisterHighByteFirstNulPadded) {
  const std::vector<std::uint16_t> regs = plc::EncodeAscii("ABC", 3);
  EXPECT_EQ(regs, (std::vector<std::uint16_t>{0x4142, 0x4300, 0x0000}));
  std::string text, why;
  ASSERT_TRUE(plc::DecodeAscii(regs.data(), 3, &text, &why)) << why;
  EXPECT_EQ(text, "ABC");
  const std::uint16_t gap[] = {0x4100, 0x4200};
  EXPECT_FALSE(plc::DecodeAscii(gap, 2, &text, &why));
  EXPECT_EQ(why, "a character follows the NUL at byte 1");
  const std::uint16_t bell[] = {0x4107};
  EXPECT_FALSE(plc::DecodeAscii(bell, 1, &text, &why));
  EXPECT_EQ(why, "byte 1 is 0x07, not printable ASCII");
}

}  // namespace
}  // namespace eol::station
