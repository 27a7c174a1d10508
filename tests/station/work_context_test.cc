// Who and what with the serial (station/daemon/test_request.h): the operator id, shift and order
// number arrive over HTTP (POST /api/tests), from the scanner's line on stdin (through the
// `eol station` binary) and are stored with the record; bad fields are refused naming the
// field. Real SQLite file, real HTTP on 127.0.0.1, the sim bench. (The line PLC's blocks
// are tested in plc_handshake_test.cc.)
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <thread>

#include "db/store.h"
#include "station/daemon/station.h"
#include "station/daemon/test_request.h"
#include "tests/support/child_process.h"
#include "tests/support/station_ready.h"
#include "tests/support/wait_until.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station {
namespace {

using namespace std::chrono_literals;

nlohmann::json StationJson(const std::string& db_path) {
  return {{"station_id", "wc"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", db_path},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}}},
          {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}}};
}

// The stored tests of `serial`, waited for (up to 120 s) until there are `n`.
std::vector<db::TestRecord> WaitStored(const std::string& db_path, const std::string& serial,
                                       std::size_t n) {
  std::vector<db::TestRecord> tests;
  eol::testing::WaitUntil(
      [&] {
        // Read-only: a reader that may create would leave an empty file the daemon then
        // refuses when the test looks before the daemon has made its store (a store still
        // being made is refused too, and looked at again).
        try {
          if (std::filesystem::exists(db_path))
            tests = db::Store::Open(db_path, db::Store::Role::kReadOnly)->TestsOfSerial(serial);
        } catch (const db::StoreError&) {
        }
        return tests.size() >= n;
      },
      120s, 50ms);
  return tests;
}

TEST(ScannerLine, TheSerialAloneOrWithTabSeparatedFields) {
  std::string why;
  auto r = ParseScannerLine("SN-1", &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->serial, "SN-1");
  EXPECT_EQ(r->work, db::WorkContext{});
  r = ParseScannerLine("SN-2\tshift=night\torder_number=PO-4711\toperator_id=op 17", &why);
  ASSERT_TRUE(r) << why;
  EXPECT_EQ(r->serial, "SN-2");  // serials allow no spaces (db/serial_number.h)
  EXPECT_EQ(r->work, (db::WorkContext{"op 17", "night", "PO-4711"}));

  EXPECT_FALSE(ParseScannerLine("SN-1\toperator=op-17", &why));
  EXPECT_EQ(why, "unknown field 'operator' (keys: operator_id, shift, order_number)");
  EXPECT_FALSE(ParseScannerLine("SN-1\tshift=A\tshift=B", &why));
  EXPECT_EQ(why, "field 'shift' given twice");
  EXPECT_FALSE(ParseScannerLine("SN-1\tPO-4711", &why));
  EXPECT_EQ(why, "field 'PO-4711' is not key=value (keys: operator_id, shift, order_number)");
  EXPECT_FALSE(ParseScannerLine("\tshift=A", &why));
  EXPECT_EQ(why, "serial is empty");
  EXPECT_FALSE(ParseScannerLine("SN-1\tshift=" + std::string(17, 'x'), &why));
  EXPECT_EQ(why, "shift: at most 16 characters (got 17)");
}

TEST(WorkContextFields, EachRuleNamesTheField) {
  std::string why;
  db::WorkContext w;
  EXPECT_TRUE(ValidWorkContext(w, &why));
  w.order_number = std::string(32, '9');
  EXPECT_TRUE(ValidWorkContext(w, &why)) << why;
  w.order_number += "9";
  EXPECT_FALSE(ValidWorkContext(w, &why));
  EXPECT_EQ(why, "order_number: at most 32 characters (got 33)");
  w = {" op", "", ""};
  EXPECT_FALSE(ValidWorkContext(w, &why));
  EXPECT_EQ(why, "operator_id: no spaces at either end");
  w = {"op\x01", "", ""};
  EXPECT_FALSE(ValidWorkContext(w, &why));
  EXPECT_EQ(why, "operator_id: character 3 is not printable ASCII");
  EXPECT_FALSE(ReadWorkContext({{"serial", "S"}, {"shift", 2}}, &w, &why));
  EXPECT_EQ(why, "shift: must be a string");
}

TEST(WorkContextHttp, PostedFieldsAreStoredAndBadOnesRefusedNamingTheField) {
  eol::testing::TempDir dir;
  const std::string db_path = dir / "wc.sqlite";
  Station station(ParseStationConfig(StationJson(db_path), "test", ""));
  station.StartHttp();
  std::thread serve([&] { station.Serve(); });
  httplib::Client http("127.0.0.1", station.http_port());
  http.set_read_timeout(10, 0);

  auto res = http.Post(
      "/api/tests", nlohmann::json{{"serial", "SN-9"}, {"shift", "B"}, {"order_number", 7}}.dump(),
      "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;
  EXPECT_EQ(nlohmann::json::parse(res->body)["error"]["code"], "bad_field");
  EXPECT_EQ(nlohmann::json::parse(res->body)["error"]["message"], "order_number: must be a string");

  res = http.Post(
      "/api/tests",
      nlohmann::json{
          {"serial", "SN-1"}, {"operator_id", "op-17"}, {"shift", "B"}, {"order_number", "PO-4711"}}
          .dump(),
      "application/json");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 202) << res->body;
  const auto tests = WaitStored(db_path, "SN-1", 1);
  station.RequestStop("test over");
  serve.join();
  ASSERT_EQ(tests.size(), 1u);
  EXPECT_EQ(tests[0].work, (db::WorkContext{"op-17", "B", "PO-4711"}));
  EXPECT_TRUE(db::Store::Open(db_path, db::Store::Role::kReader)->TestsOfSerial("SN-9").empty());
}

TEST(WorkContextScanner, TheDaemonReadsTheScannersLineFromStdinAndStoresTheFields) {
  eol::testing::TempDir dir;
  const std::string db_path = dir / "scan.sqlite";
  nlohmann::json config = StationJson(db_path);
  config["serial_from_stdin"] = true;
  std::ofstream(dir / "station.json") << config.dump();
  // A refused line first, then a good one (the station is idle again by then).
  std::ofstream(dir / "scans.txt") << "SN-X\toperator=op-1\n"
                                   << "SN-2\toperator_id=op-5\tshift=A\torder_number=PO-1\r\n";
  // exec: the shell becomes the daemon, so the test stops it by its own pid.
  eol::testing::ChildProcess daemon({"/bin/sh", "-c",
                                     "exec \"$0\" station --config \"$1\" < \"$2\"", EOL_BINARY,
                                     dir / "station.json", dir / "scans.txt"});
  const auto tests = WaitStored(db_path, "SN-2", 1);
  EXPECT_TRUE(daemon.WaitFor(
      [](const std::string& out) {
        return out.find("unknown field 'operator'") != std::string::npos;
      },
      10s))
      << daemon.output();
  EXPECT_EQ(daemon.Stop(SIGTERM, 30s), 0) << daemon.output();
  ASSERT_EQ(tests.size(), 1u) << daemon.output();
  EXPECT_EQ(tests[0].work, (db::WorkContext{"op-5", "A", "PO-1"}));
  EXPECT_TRUE(db::Store::Open(db_path, db::Store::Role::kReader)->TestsOfSerial("SN-X").empty());
}

}  // namespace
}  // namespace eol::station
