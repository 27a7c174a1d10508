// Issue 34: a plant URL with `user:password@` was accepted and its password logged on every
// reconnect. RedactUrl is what every message that prints a URL shows; the MQTT URL refuses
// user-info (its credentials have fields of their own); a publisher's log lines never carry
// a password, whatever its host holds.
#include <gtest/gtest.h>
#include <spdlog/sinks/ringbuffer_sink.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <thread>

#include "db/store.h"
#include "station/daemon/config.h"
#include "station/daemon/mqtt_publisher.h"
#include "station/daemon/plant_urls.h"
#include "tests/support/child_process.h"
#include "tests/support/free_port.h"
#include "tests/support/wait_until.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;

TEST(RedactUrl, HidesThePasswordOfAnyUrlAndConninfo) {
  EXPECT_EQ(RedactUrl("mqtt://line:s3cret@broker:1883"), "mqtt://line:***@broker:1883");
  EXPECT_EQ(RedactUrl("postgresql://eol:p@ss@db:5432/plant"), "postgresql://eol:***@db:5432/plant");
  EXPECT_EQ(RedactUrl("postgresql://eol@db/plant"), "postgresql://eol@db/plant");
  EXPECT_EQ(RedactUrl("mqtts://broker:8883/x@y"), "mqtts://broker:8883/x@y");
  EXPECT_EQ(RedactUrl("host=db password='a b' user=eol"), "host=db password=*** user=eol");
  EXPECT_EQ(RedactUrl("host=db password=s3cret"), "host=db password=***");
}

TEST(ParseMqttUrl, RefusesUserInfoNamingTheFieldsAndNeverShowsThePassword) {
  std::string host, why;
  int port = 0;
  bool tls = false;
  EXPECT_FALSE(ParseMqttUrl("mqtt://line:s3cret@broker:1883", &host, &port, &tls, &why));
  EXPECT_EQ(why.find("s3cret"), std::string::npos) << why;
  EXPECT_NE(why.find("\"username\""), std::string::npos) << why;
  EXPECT_NE(why.find("\"password\""), std::string::npos) << why;
  EXPECT_FALSE(ParseMqttUrl("mqtts://only-user@broker", &host, &port, &tls, &why));
  EXPECT_FALSE(ParseMqttUrl("http://u:s3cret@broker", &host, &port, &tls, &why));
  EXPECT_EQ(why.find("s3cret"), std::string::npos) << why;
  EXPECT_TRUE(ParseMqttUrl("mqtt://broker:1884", &host, &port, &tls, &why)) << why;
  EXPECT_EQ(host, "broker");
  EXPECT_EQ(port, 1884);
}

TEST(ParseMqttUrl, TheConfigRefusesUserInfoAndTakesTheFields) {
  nlohmann::json j = {{"recipe", "r.json"},
                      {"db", "x.sqlite"},
                      {"fixture", {{"driver", "sim"}}},
                      {"daq", {{"driver", "sim"}}}};
  j["mqtt"] = {{"url", "mqtt://line:s3cret@broker:1883"}};
  try {
    ParseStationConfig(j, "station.json", "");
    ADD_FAILURE() << "accepted";
  } catch (const std::exception& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.find("s3cret"), std::string::npos) << what;
    EXPECT_NE(what.find("/mqtt/url"), std::string::npos) << what;
    EXPECT_NE(what.find("\"password\""), std::string::npos) << what;
  }
  j["mqtt"] = {{"url", "mqtt://broker:1883"}, {"username", "line"}, {"password", "s3cret"}};
  const auto c = ParseStationConfig(j, "station.json", "");
  EXPECT_EQ(c.mqtt->username, "line");
  EXPECT_EQ(c.mqtt->password, "s3cret");
}

TEST(MqttPublisher, ItsReconnectLogNeverShowsAPassword) {
  auto ring = std::make_shared<spdlog::sinks::ringbuffer_sink_mt>(64);
  const auto previous = spdlog::default_logger();
  spdlog::set_default_logger(std::make_shared<spdlog::logger>("capture", ring));
  eol::testing::TempDir dir;
  db::Store::Open(dir / "s.sqlite");
  {
    MqttConfig q;
    q.host = "line:s3cret@127.0.0.1";   // as a URL's user-info would have reached it
    q.port = eol::testing::FreePort();  // nobody listens: every attempt fails and is logged
    q.username = "line";
    q.password = "s3cret";
    q.reconnect_s = 0.05;
    MqttPublisher p(q, "eol-t", dir / "s.sqlite", [] { return "idle"; });
    try {
      p.Start();
      eol::testing::WaitUntil([&] { return !ring->last_formatted().empty(); }, 3000ms);
    } catch (const std::exception& e) {
      spdlog::error("{}", e.what());
    }
  }
  spdlog::set_default_logger(previous);
  const auto lines = ring->last_formatted();
  ASSERT_FALSE(lines.empty());
  for (const std::string& line : lines) EXPECT_EQ(line.find("s3cret"), std::string::npos) << line;
}

}  // namespace
}  // namespace eol::station
