// The line PLC's Modbus server (station/daemon/plc/plc_server.h) under a crowd on 127.0.0.1: idle,
// slow, malformed and connect-and-close clients around one well-behaved PLC, with a station
// backend of the test's own. Issue 34: four idle connections killed the daemon; a PLC
// sending a byte every 0.4 s stalled every other for 4.4 s per frame.
#include <gtest/gtest.h>

#include <iostream>

#include "station/daemon/config.h"
#include "station/daemon/plc/plc_server.h"
#include "tests/support/modbus_crowd.h"

namespace eol::station::plc {
namespace {

using namespace std::chrono_literals;

PlcBackend Backend() {
  PlcBackend b;
  b.start = [](const TestRequest&) { return PlcStartReply{PlcRefusal::kBusy, "test", 0}; };
  b.view = [] { return PlcStationView{}; };
  return b;
}

TEST(PlcCrowd, EightIdleSlowAndMalformedClientsLeaveAWellBehavedPlcServed) {
  PlcServerSettings s;
  s.listen = "127.0.0.1";
  s.port = 0;
  s.max_clients = 16;
  s.frame_deadline = 5000ms;  // the slow clients' requests are answered
  PlcServer server(s, Backend());
  server.Start();
  eol::testing::CrowdPlan plan;
  plan.port = server.port();
  plan.unit = s.unit_id;
  plan.function = 3;
  plan.address = s.map.serial;
  const auto f = eol::testing::RunCrowd(plan);
  std::cout << "PLC server crowd: " << eol::testing::Describe(plan, f) << "\n";
  EXPECT_EQ(f.idle_connected, 8);
  EXPECT_EQ(f.good_answered, plan.good_requests);
  EXPECT_LT(f.good_max_ms, 100.0);
  EXPECT_EQ(f.slow_answered, plan.slow);
  EXPECT_GT(f.malformed_sent, 0);
}

TEST(PlcCrowd, ASlowPlcIsCutOffAtTheFrameDeadlineAndTheCapRefusesTheExtra) {
  PlcServerSettings s;
  s.listen = "127.0.0.1";
  s.port = 0;
  s.max_clients = 2;
  s.frame_deadline = 300ms;
  s.idle_timeout = 60s;
  PlcServer server(s, Backend());
  server.Start();
  const int slow = eol::testing::ConnectModbus(server.port());
  const int good = eol::testing::ConnectModbus(server.port());
  ASSERT_TRUE(eol::testing::SendAll(slow, {0, 1, 0}));  // and nothing more
  const int extra = eol::testing::ConnectModbus(server.port());
  EXPECT_TRUE(eol::testing::ClosedByServer(extra, 1000ms)) << "a third client over a cap of 2";
  ASSERT_TRUE(eol::testing::SendAll(good, eol::testing::ReadRequest(5, 1, 3, s.map.serial, 1)));
  EXPECT_EQ(eol::testing::ReadReply(good, 100ms).size(), 11u) << "the slow one stalls nobody";
  EXPECT_TRUE(eol::testing::ClosedByServer(slow, 1000ms));
  const int next = eol::testing::ConnectModbus(server.port());
  ASSERT_TRUE(eol::testing::SendAll(next, eol::testing::ReadRequest(6, 1, 3, s.map.serial, 1)));
  EXPECT_EQ(eol::testing::ReadReply(next, 500ms).size(), 11u) << "the slow one's slot is free";
  for (int fd : {slow, good, extra, next}) ::close(fd);
}

TEST(PlcCrowd, TheConfigListensOnLoopbackUnlessToldAndSetsTheDeadlines) {
  const nlohmann::json base = {{"recipe", "r.json"},
                               {"db", "x.sqlite"},
                               {"fixture", {{"driver", "sim"}}},
                               {"daq", {{"driver", "sim"}}}};
  nlohmann::json j = base;
  j["plc"] = nlohmann::json::object();
  EXPECT_EQ(ParseStationConfig(j, "t", "").plc->listen, "127.0.0.1");
  j["plc"] = {{"listen", "10.0.0.5"}, {"frame_deadline_ms", 250}, {"idle_timeout_s", 5}};
  const auto c = ParseStationConfig(j, "t", "");
  EXPECT_EQ(c.plc->listen, "10.0.0.5");
  EXPECT_EQ(c.plc->frame_deadline, 250ms);
  EXPECT_EQ(c.plc->idle_timeout, 5000ms);
  j["plc"] = {{"frame_deadline_ms", 0}};
  EXPECT_THROW(ParseStationConfig(j, "t", ""), std::exception);
}

}  // namespace
}  // namespace eol::station::plc
