// Results over MQTT from the store's outbox (station/daemon/mqtt_publisher.h) against a real
// mosquitto broker started by the test on a free port, and an independent subscriber (Debian's
// python3-paho-mqtt, tests/peers/mqtt_subscriber.py) in a persistent session. The broker is
// stopped and restarted in the middle of a run: nothing is lost, the order is kept, and a
// daemon killed with SIGKILL leaves its last will "offline".
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "db/store.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"
#include "tests/support/free_port.h"
#include "tests/support/mosquitto_broker.h"
#include "tests/support/mqtt_mes.h"
#include "tests/support/wait_until.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::FreePort;
using eol::testing::MesArgv;
using eol::testing::Messages;
using eol::testing::MosquittoBroker;
using eol::testing::Received;
using eol::testing::ResultIds;

double UnixNow() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

nlohmann::json StationJson(const std::string& db_path, int broker_port) {
  return {{"station_id", "mq-1"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", db_path},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}}},
          {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}},
          {"mqtt",
           {{"url", "mqtt://127.0.0.1:" + std::to_string(broker_port)},
            {"topic_prefix", "plant/eol"},
            {"reconnect_s", 0.2}}}};
}

class MqttResultsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_GT(port_, 0);
    ASSERT_TRUE(broker_.Start());
    subscriber_ = std::make_unique<ChildProcess>(MesArgv(port_, "plant/eol/#"));
    ASSERT_TRUE(eol::testing::WaitSubscribed(*subscriber_, 20s))
        << "the subscriber (python3-paho-mqtt) did not subscribe: " << subscriber_->output();
  }
  void TearDown() override {
    subscriber_.reset();
    broker_.Stop();
  }

  // Waits until the subscriber has `n` distinct results (or 120 s).
  std::vector<std::int64_t> WaitResults(std::size_t n, int* duplicates) {
    std::vector<std::int64_t> ids;
    eol::testing::WaitUntil(
        [&] {
          ids = ResultIds(Messages(*subscriber_), "plant/eol/mq-1/result", duplicates);
          return ids.size() >= n;
        },
        120s);
    return ids;
  }

  eol::testing::TempDir dir_;
  const int port_ = FreePort();
  MosquittoBroker broker_{dir_.path(), port_};
  std::unique_ptr<ChildProcess> subscriber_;
};

TEST_F(MqttResultsTest, ABrokerOutageInTheMiddleOfARunLosesNothingAndKeepsTheOrder) {
  const std::string db_path = dir_ / "mq.sqlite";
  auto owned =
      std::make_unique<Station>(ParseStationConfig(StationJson(db_path, port_), "test", ""));
  Station& station = *owned;
  station.StartMqtt();

  // Online: each stored record arrives; the delay from stored to received.
  double worst_delay_s = 0;
  for (int i = 1; i <= 3; ++i) {
    const db::TestRecord r = station.RunTest("ON-" + std::to_string(i));
    ASSERT_NE(r.id, 0);
    const double stored_at = UnixNow();
    int dup = 0;
    ASSERT_EQ(WaitResults(static_cast<std::size_t>(i), &dup).size(), static_cast<std::size_t>(i));
    for (const Received& m : Messages(*subscriber_))
      if (m.topic == "plant/eol/mq-1/result" && nlohmann::json::parse(m.payload)["id"] == r.id)
        worst_delay_s = std::max(worst_delay_s, m.t - stored_at);
  }

  // The broker goes away: tests go on, records wait in the outbox.
  broker_.Stop();
  for (int i = 1; i <= 3; ++i) ASSERT_NE(station.RunTest("OFF-" + std::to_string(i)).id, 0);
  constexpr int kBacklog = 1000;
  {
    // A long outage's backlog, written through a connection of the test's own.
    auto writer = db::Store::Open(db_path, db::Store::Role::kReader);
    const db::TestRecord like = writer->Tests(db::TestQuery{}).front();
    for (int i = 0; i < kBacklog; ++i) {
      db::TestRecord r = like;
      r.serial = "BACKLOG-" + std::to_string(i);
      writer->Insert(r);
    }
  }
  auto reader = db::Store::Open(db_path, db::Store::Role::kReader);
  const std::int64_t pending = reader->OutboxPending("mqtt");
  EXPECT_EQ(pending, 3 + kBacklog);

  // The broker returns: the outbox replays in order, then the run goes on.
  ASSERT_TRUE(broker_.Start());
  const auto t0 = std::chrono::steady_clock::now();
  eol::testing::WaitUntil([&] { return reader->OutboxPending("mqtt") == 0; }, 300s, 10ms);
  const double replay_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  ASSERT_EQ(reader->OutboxPending("mqtt"), 0);
  for (int i = 1; i <= 3; ++i) ASSERT_NE(station.RunTest("BACK-" + std::to_string(i)).id, 0);

  const std::size_t total = 3 + 3 + kBacklog + 3;
  int duplicates = 0;
  const std::vector<std::int64_t> ids = WaitResults(total, &duplicates);
  // Store order (ids grow with the outbox here), each record once at least.
  std::vector<std::int64_t> stored;
  for (const auto& e : reader->OutboxAfterCursor("nobody", 10000)) stored.push_back(e.test_id);
  if (ids.size() != total) {
    const std::set<std::int64_t> got(ids.begin(), ids.end());
    std::ostringstream missing;
    for (const std::int64_t id : stored)
      if (!got.count(id)) missing << " " << id << " (" << reader->Test(id, false)->serial << ")";
    FAIL() << ids.size() << " of " << total << " results received; lost:" << missing.str()
           << "\nbroker: " << broker_.output();
  }
  EXPECT_EQ(ids, stored) << "order or content differs from the outbox";
  // The payload is the stored record.
  const auto messages = Messages(*subscriber_);
  for (const Received& m : messages) {
    if (m.topic != "plant/eol/mq-1/result") continue;
    const auto j = nlohmann::json::parse(m.payload);
    if (j["serial"] != "OFF-2") continue;
    const auto rec = reader->TestsOfSerial("OFF-2").at(0);
    EXPECT_EQ(j["id"], rec.id);
    EXPECT_EQ(j["station_id"], "mq-1");
    EXPECT_EQ(j["outcome"], analysis::ToString(rec.outcome));
    EXPECT_FALSE(j.contains("curves"));
  }
  std::cout << "[ figures  ] stored -> received (online, worst of 3): " << worst_delay_s * 1e3
            << " ms; replay of " << pending << " records after the outage: " << replay_s << " s ("
            << pending / replay_s << " records/s); duplicates: " << duplicates << "\n";

  // The status: online with the sequencer's state while it runs, "offline" at a clean stop.
  owned.reset();
  std::vector<std::string> status;
  for (const Received& m : Messages(*subscriber_))
    if (m.topic == "plant/eol/mq-1/status") status.push_back(m.payload);
  ASSERT_GE(status.size(), 2u);
  EXPECT_EQ(nlohmann::json::parse(status.front())["online"], true) << status.front();
  EXPECT_EQ(status.back(), "offline");
}

TEST_F(MqttResultsTest, ADaemonKilledLeavesItsLastWillOfflineRetained) {
  const std::string db_path = dir_ / "will.sqlite";
  std::ofstream(dir_ / "station.json") << StationJson(db_path, port_).dump();
  ChildProcess daemon({EOL_BINARY, "station", "--config", dir_ / "station.json"});
  auto status = [&] {
    std::vector<std::string> s;
    for (const Received& m : Messages(*subscriber_))
      if (m.topic == "plant/eol/mq-1/status") s.push_back(m.payload);
    return s;
  };
  eol::testing::WaitUntil([&] { return !status().empty(); }, 30s);
  daemon.WaitFor([](const std::string&) { return false; }, 100ms);
  ASSERT_FALSE(status().empty()) << daemon.output() << "\nsubscriber: " << subscriber_->output()
                                 << "\nbroker: " << broker_.output();
  EXPECT_EQ(nlohmann::json::parse(status().back())["state"], "idle");
  daemon.Stop(SIGKILL, 10s);
  eol::testing::WaitUntil([&] { return status().back() == "offline"; }, 30s);
  EXPECT_EQ(status().back(), "offline") << "no last will after SIGKILL";
  // Retained: a client that subscribes now still reads it.
  ChildProcess late(MesArgv(port_, "plant/eol/mq-1/status", {"--client-id", "late-reader"}));
  EXPECT_TRUE(late.WaitFor(
      [](const std::string& o) { return o.find("\"payload\": \"offline\"") != std::string::npos; },
      20s))
      << late.output();
}

// A test CA and a server certificate for 127.0.0.1 and localhost, made by openssl now.
void MakeCertificates(const std::string& dir, const std::string& ca_name) {
  const auto run = [](std::vector<std::string> argv) {
    ChildProcess p(argv);
    const auto rc = p.Wait(60s);
    ASSERT_TRUE(rc && *rc == 0) << argv[1] << ": " << p.output();
  };
  const std::string openssl = "/usr/bin/openssl";
  std::ofstream(dir + "/san.cnf") << "subjectAltName=IP:127.0.0.1,DNS:localhost\n";
  run({openssl, "req", "-x509", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1",
       "-nodes", "-keyout", dir + "/" + ca_name + ".key", "-out", dir + "/" + ca_name + ".crt",
       "-days", "2", "-subj", "/CN=eol test " + ca_name});
  run({openssl, "req", "-newkey", "ec", "-pkeyopt", "ec_paramgen_curve:prime256v1", "-nodes",
       "-keyout", dir + "/server.key", "-out", dir + "/server.csr", "-subj", "/CN=localhost"});
  run({openssl, "x509", "-req", "-in", dir + "/server.csr", "-CA", dir + "/" + ca_name + ".crt",
       "-CAkey", dir + "/" + ca_name + ".key", "-CAcreateserial", "-out", dir + "/server.crt",
       "-days", "2", "-extfile", dir + "/san.cnf"});
}

class MqttTlsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    ASSERT_EQ(access("/usr/bin/openssl", X_OK), 0) << "openssl is a declared test dependency";
    ASSERT_TRUE(broker_.Start());
  }
  MqttConfig Config(const std::string& ca_file) {
    MqttConfig c;
    c.host = "127.0.0.1";
    c.port = port_;
    c.reconnect_s = 0.2;
    c.tls = MqttTls{ca_file, "", "", false};
    return c;
  }
  eol::testing::TempDir dir_;
  const int port_ = FreePort();
  MosquittoBroker broker_{
      dir_.path(), port_,
      "cafile BROKER/ca.crt\ncertfile BROKER/server.crt\nkeyfile BROKER/server.key\n",
      [](const std::string& d) { MakeCertificates(d, "ca"); }};
};

TEST_F(MqttTlsTest, ResultsGoOverTlsCheckedAgainstTheConfiguredCa) {
  const std::string ca = broker_.dir() + "/ca.crt";
  ChildProcess mes(MesArgv(port_, "plant/eol/#", {"--cafile", ca}));
  ASSERT_TRUE(eol::testing::WaitSubscribed(mes, 20s))
      << mes.output() << "\nbroker: " << broker_.output();
  const std::string db_path = dir_ / "tls.sqlite";
  {
    auto store = db::Store::Open(db_path);
    db::TestRecord r;
    r.serial = "TLS-1";
    r.station_id = "tls-1";
    r.recipe_id = "r";
    r.recipe_hash = std::string(64, 'b');
    r.started_at = r.finished_at = "2026-01-01T00:00:00.000Z";
    r.outcome = analysis::Outcome::kPass;
    store->Insert(r);
  }
  MqttPublisher publisher(Config(ca), "tls-1", db_path, [] { return std::string("idle"); });
  publisher.Start();
  EXPECT_TRUE(
      mes.WaitFor([](const std::string& o) { return o.find("TLS-1") != std::string::npos; }, 30s))
      << mes.output() << "\nbroker: " << broker_.output();
  EXPECT_TRUE(publisher.connected());
  auto reader = db::Store::Open(db_path, db::Store::Role::kReader);
  eol::testing::WaitUntil([&] { return reader->OutboxPending("mqtt") == 0; }, 10s, 10ms);
  EXPECT_EQ(reader->OutboxPending("mqtt"), 0) << "acknowledged over TLS";
  publisher.Stop();

  // A broker whose certificate does not chain to the configured CA: never connected, the
  // record stays in the outbox.
  const std::string other = dir_ / "other";
  std::filesystem::create_directory(other);
  MakeCertificates(other, "other-ca");
  {
    auto store = db::Store::Open(db_path);
    db::TestRecord r = store->Tests(db::TestQuery{}).front();
    r.serial = "TLS-2";
    store->Insert(r);
  }
  MqttPublisher wrong(Config(other + "/other-ca.crt"), "tls-1", db_path,
                      [] { return std::string("idle"); });
  const std::size_t broker_log = broker_.output().size();
  wrong.Start();
  // The broker saw the handshake the publisher refused (its certificate is not trusted).
  EXPECT_TRUE(eol::testing::WaitUntil(
      [&] { return broker_.output().find("OpenSSL Error", broker_log) != std::string::npos; }, 30s))
      << "broker: " << broker_.output();
  EXPECT_FALSE(wrong.connected());
  wrong.Stop();
  EXPECT_EQ(reader->OutboxPending("mqtt"), 1) << "TLS-2 waits for a broker it can trust";
  EXPECT_EQ(mes.output().find("TLS-2"), std::string::npos);
}

TEST(MqttTlsConfigTest, TheConfigNamesTheFieldOfAMissingFileOrAMismatch) {
  eol::testing::TempDir dir;
  std::ofstream(dir / "ca.crt") << "-----BEGIN CERTIFICATE-----\n";
  const auto parse = [&](const nlohmann::json& mqtt) {
    nlohmann::json j = StationJson(dir / "x.sqlite", 1883);
    j["mqtt"] = mqtt;
    try {
      ParseStationConfig(j, "test", dir.path());
      return std::string();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
  };
  EXPECT_EQ(parse({{"url", "mqtts://broker:8883"}, {"tls", {{"ca_file", "ca.crt"}}}}), "");
  const std::string missing =
      parse({{"url", "mqtts://broker"}, {"tls", {{"ca_file", "/nonexistent/ca.crt"}}}});
  EXPECT_NE(missing.find("/mqtt/tls/ca_file"), std::string::npos) << missing;
  EXPECT_NE(missing.find("/nonexistent/ca.crt"), std::string::npos) << missing;
  const std::string key =
      parse({{"url", "mqtts://broker"}, {"tls", {{"ca_file", "ca.crt"}, {"cert_file", "ca.crt"}}}});
  EXPECT_NE(key.find("/mqtt/tls/key_file"), std::string::npos) << key;
  const std::string plain = parse({{"url", "mqtt://broker"}, {"tls", {{"ca_file", "ca.crt"}}}});
  EXPECT_NE(plain.find("/mqtt/tls"), std::string::npos) << plain;
  EXPECT_NE(plain.find("mqtts://"), std::string::npos) << plain;
  const std::string unknown =
      parse({{"url", "mqtts://broker"}, {"tls", {{"ca_file", "ca.crt"}, {"verify", false}}}});
  EXPECT_NE(unknown.find("/mqtt/tls/verify"), std::string::npos) << unknown;
  // mqtts:// alone: the system's CAs, port 8883.
  nlohmann::json j = StationJson(dir / "x.sqlite", 1883);
  j["mqtt"] = {{"url", "mqtts://broker"}};
  const StationConfig c = ParseStationConfig(j, "test", dir.path());
  ASSERT_TRUE(c.mqtt && c.mqtt->tls);
  EXPECT_EQ(c.mqtt->port, 8883);
  EXPECT_EQ(c.mqtt->tls->ca_file, "");
}

}  // namespace
}  // namespace eol::station
