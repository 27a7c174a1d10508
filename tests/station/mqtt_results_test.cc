// Results over MQTT from the store's outbox (station/mqtt_publisher.h) against a real
// mosquitto broker started by the test on a free port, and an independent subscriber (Debian's
// python3-paho-mqtt, tests/peers/mqtt_subscriber.py) in a persistent session. The broker is
// stopped and restarted in the middle of a run: nothing is lost, the order is kept, and a
// daemon killed with SIGKILL leaves its last will "offline".
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <pwd.h>
#include <sys/socket.h>
#include <sys/stat.h>
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
#include "station/station.h"
#include "tests/support/child_process.h"
#include "tests/support/station_ready.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

constexpr const char* kMosquitto = "/usr/sbin/mosquitto";
constexpr const char* kPython = "/usr/bin/python3";

// A port nobody listens on now (the kernel's pick; the broker binds it right after).
int FreePort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  socklen_t len = sizeof a;
  if (bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0 ||
      getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0) {
    close(fd);
    return 0;
  }
  close(fd);
  return ntohs(a.sin_port);
}

// mosquitto on 127.0.0.1:port with persistence in `dir` (what it holds survives a restart:
// the MES's persistent session with its subscription and queued messages).
//
// Started as root, mosquitto drops its privileges to the `mosquitto` user after reading its
// config, and writes its persistence file as that user. In the test's own directory (root's,
// 0700) its save on SIGTERM failed ("Error saving in-memory database ... Permission denied"),
// the restarted broker had no session for the MES, and what the station published before the
// MES had subscribed again went to nobody, acknowledged. So the broker's directory belongs to
// the user it runs as, and Stop() checks that the save worked.
class Broker {
 public:
  // `listener_extra`: lines after the listener (its TLS files; "BROKER" stands for dir()),
  // given a prepare step that writes files into dir() first (they are given to the broker's
  // user too).
  Broker(std::string dir, int port, std::string listener_extra = "",
         const std::function<void(const std::string&)>& prepare = {})
      : dir_(std::move(dir) + "/broker"), port_(port) {
    std::filesystem::create_directory(dir_);
    if (geteuid() == 0) {
      if (const passwd* pw = getpwnam("mosquitto")) {
        chmod(std::filesystem::path(dir_).parent_path().c_str(), 0711);
        if (chown(dir_.c_str(), pw->pw_uid, pw->pw_gid) != 0) ADD_FAILURE() << "chown " << dir_;
      }
    }
    if (prepare) prepare(dir_);
    for (std::size_t at; (at = listener_extra.find("BROKER")) != std::string::npos;)
      listener_extra.replace(at, 6, dir_);
    if (geteuid() == 0)
      if (const passwd* pw = getpwnam("mosquitto"))
        for (const auto& f : std::filesystem::directory_iterator(dir_))
          if (chown(f.path().c_str(), pw->pw_uid, pw->pw_gid) != 0) ADD_FAILURE() << f.path();
    std::ofstream(dir_ + "/mosquitto.conf")
        << "listener " << port_ << " 127.0.0.1\n"
        << listener_extra << "allow_anonymous true\npersistence true\n"
        << "persistence_location " << dir_
        << "/\n"
        // The MES's session queues the whole replay while it reconnects (mosquitto drops
        // QoS 1 messages beyond 1000 queued per client by default).
        << "max_queued_messages 100000\n";
  }
  ::testing::AssertionResult Start() {
    if (access(kMosquitto, X_OK) != 0)
      return ::testing::AssertionFailure()
             << kMosquitto << " not found: mosquitto is a declared test dependency "
             << "(apt-get install mosquitto)";
    process_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{kMosquitto, "-c", dir_ + "/mosquitto.conf"});
    if (!process_->WaitFor(
            [](const std::string& o) { return o.find(" running") != std::string::npos; }, 10s))
      return ::testing::AssertionFailure() << "mosquitto did not start: " << process_->output();
    return ::testing::AssertionSuccess();
  }
  // SIGTERM: mosquitto saves its sessions to persistence_location, then exits. A failed
  // save fails the test: the next start would have lost the sessions.
  void Stop() {
    if (!process_) return;
    process_->Stop(SIGTERM, 10s);
    EXPECT_EQ(process_->output().find("Error saving"), std::string::npos) << process_->output();
    EXPECT_TRUE(std::filesystem::exists(dir_ + "/mosquitto.db"))
        << "mosquitto saved no persistence file: " << process_->output();
    process_.reset();
  }
  int port() const { return port_; }
  const std::string& dir() const { return dir_; }
  std::string output() {
    if (!process_) return "";
    process_->WaitFor([](const std::string&) { return false; }, 50ms);
    return process_->output();
  }

 private:
  std::string dir_;
  int port_;
  std::unique_ptr<ChildProcess> process_;
};

// The MES: every message it received, parsed from its output.
struct Received {
  std::string topic;
  std::string payload;
  double t = 0;  // unix seconds, when it arrived
};

std::vector<Received> Messages(ChildProcess& sub) {
  sub.WaitFor([](const std::string&) { return false; }, 20ms);  // read what is there
  std::vector<Received> out;
  std::istringstream in(sub.output());
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line.front() != '{') continue;
    const auto j = nlohmann::json::parse(line, nullptr, false);
    if (j.is_discarded() || j.value("event", "") != "message") continue;
    out.push_back({j["topic"], j["payload"], j["t"]});
  }
  return out;
}

// Test ids of the result messages, first arrivals in arrival order, and how many repeated.
std::vector<std::int64_t> ResultIds(const std::vector<Received>& all, const std::string& topic,
                                    int* duplicates) {
  std::vector<std::int64_t> ids;
  std::set<std::int64_t> seen;
  *duplicates = 0;
  for (const Received& m : all) {
    if (m.topic != topic) continue;
    const auto j = nlohmann::json::parse(m.payload);
    const std::int64_t id = j.at("id");
    if (seen.insert(id).second)
      ids.push_back(id);
    else
      ++*duplicates;
  }
  return ids;
}

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
    subscriber_ = std::make_unique<ChildProcess>(std::vector<std::string>{
        kPython, std::string(EOL_SOURCE_DIR) + "/tests/peers/mqtt_subscriber.py", "--port",
        std::to_string(port_), "--topic", "plant/eol/#"});
    ASSERT_TRUE(subscriber_->WaitFor(
        [](const std::string& o) { return o.find("\"subscribed\"") != std::string::npos; }, 20s))
        << "the subscriber (python3-paho-mqtt) did not subscribe: " << subscriber_->output();
  }
  void TearDown() override {
    subscriber_.reset();
    broker_.Stop();
  }

  // Waits until the subscriber has `n` distinct results (or 120 s).
  std::vector<std::int64_t> WaitResults(std::size_t n, int* duplicates) {
    const auto deadline = std::chrono::steady_clock::now() + 120s;
    std::vector<std::int64_t> ids;
    while (std::chrono::steady_clock::now() < deadline) {
      ids = ResultIds(Messages(*subscriber_), "plant/eol/mq-1/result", duplicates);
      if (ids.size() >= n) break;
      std::this_thread::sleep_for(20ms);
    }
    return ids;
  }

  eol::testing::TempDir dir_;
  const int port_ = FreePort();
  Broker broker_{dir_.path(), port_};
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
  while (reader->OutboxPending("mqtt") > 0 && std::chrono::steady_clock::now() - t0 < 300s)
    std::this_thread::sleep_for(10ms);
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
  const auto deadline = std::chrono::steady_clock::now() + 30s;
  while (status().empty() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(20ms);
  daemon.WaitFor([](const std::string&) { return false; }, 100ms);
  ASSERT_FALSE(status().empty()) << daemon.output() << "\nsubscriber: " << subscriber_->output()
                                 << "\nbroker: " << broker_.output();
  EXPECT_EQ(nlohmann::json::parse(status().back())["state"], "idle");
  daemon.Stop(SIGKILL, 10s);
  const auto until = std::chrono::steady_clock::now() + 30s;
  while (status().back() != "offline" && std::chrono::steady_clock::now() < until)
    std::this_thread::sleep_for(20ms);
  EXPECT_EQ(status().back(), "offline") << "no last will after SIGKILL";
  // Retained: a client that subscribes now still reads it.
  ChildProcess late({kPython, std::string(EOL_SOURCE_DIR) + "/tests/peers/mqtt_subscriber.py",
                     "--port", std::to_string(port_), "--topic", "plant/eol/mq-1/status",
                     "--client-id", "late-reader"});
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
  Broker broker_{dir_.path(), port_,
                 "cafile BROKER/ca.crt\ncertfile BROKER/server.crt\nkeyfile BROKER/server.key\n",
                 [](const std::string& d) { MakeCertificates(d, "ca"); }};
};

TEST_F(MqttTlsTest, ResultsGoOverTlsCheckedAgainstTheConfiguredCa) {
  const std::string ca = broker_.dir() + "/ca.crt";
  ChildProcess mes({kPython, std::string(EOL_SOURCE_DIR) + "/tests/peers/mqtt_subscriber.py",
                    "--port", std::to_string(port_), "--topic", "plant/eol/#", "--cafile", ca});
  ASSERT_TRUE(mes.WaitFor(
      [](const std::string& o) { return o.find("\"subscribed\"") != std::string::npos; }, 20s))
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
  const auto t0 = std::chrono::steady_clock::now();
  while (reader->OutboxPending("mqtt") > 0 && std::chrono::steady_clock::now() - t0 < 10s)
    std::this_thread::sleep_for(10ms);
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
  wrong.Start();
  std::this_thread::sleep_for(2s);
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
