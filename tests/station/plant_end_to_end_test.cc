// The plant end to end (issue 15, "done when"): ONE station in-process (simulated fixture and
// DAQ, time scale 0) with both an "mqtt" and a "central" block, against a real mosquitto
// (tests/support/mosquitto_broker.h, an independent MES subscribed in a persistent QoS 1
// session, tests/support/mqtt_mes.h) and a real PostgreSQL 15 (tests/support/postgres_server.h),
// all started by the test. In the middle of the run both servers are stopped (mosquitto with
// SIGTERM, which saves its sessions; PostgreSQL as `pg_ctl stop -m immediate`); the station keeps
// testing without waiting on either, is itself destroyed and made again on the same SQLite file
// while they are down, tests on, then both servers return and the run goes on. At the end:
// every test id of the station's SQLite is in the central `tests` table exactly once and
// nothing else is there, and every one reached the MES, in store order (QoS 1 may repeat a
// record: repeats are counted and printed, deduplicated by the record's "id").
#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <future>
#include <iostream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "db/store.h"
#include "station/daemon/config.h"
#include "station/daemon/station.h"
#include "tests/support/central_counts.h"
#include "tests/support/child_process.h"
#include "tests/support/free_port.h"
#include "tests/support/mosquitto_broker.h"
#include "tests/support/mqtt_mes.h"
#include "tests/support/postgres_server.h"
#include "tests/support/wait_until.h"

namespace eol::station {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::FreePort;
using eol::testing::MosquittoBroker;
using eol::testing::PostgresServer;
using eol::testing::TempDir;
using eol::testing::WaitUntil;

constexpr const char* kStationId = "e2e-1";
constexpr const char* kResultTopic = "plant/eol/e2e-1/result";
constexpr int kPerPhase = 5;         // tests in each of the four phases
constexpr double kMaxTestS = 10.0;   // a test that takes longer waited on a server
constexpr auto kDrainTimeout = 30s;  // for a backlog of a few tens of records

using Clock = std::chrono::steady_clock;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// When the outbox backlog of "mqtt" and of "central" was first seen at 0, watched on a thread
// of its own (its own SQLite connection, polled every 5 ms) for at most `timeout`, so that
// neither waits for the other's server to start; a consumer absent from the answer never got
// there.
std::future<std::map<std::string, Clock::time_point>> WatchDrain(
    const std::string& db_path, std::chrono::milliseconds timeout) {
  return std::async(std::launch::async, [db_path, timeout] {
    auto store = db::Store::Open(db_path, db::Store::Role::kReader);
    std::map<std::string, Clock::time_point> at;
    const auto end = Clock::now() + timeout;
    while (at.size() < 2 && Clock::now() < end) {
      for (const char* consumer : {"mqtt", "central"})
        if (!at.count(consumer) && store->OutboxPending(consumer) == 0) at[consumer] = Clock::now();
      std::this_thread::sleep_for(5ms);
    }
    return at;
  });
}

// The station's config: sim bench at time scale 0, results to the test's broker, records to
// the test's PostgreSQL with fast retries (as central_record_test's Fast()).
nlohmann::json StationJson(const std::string& db_path, int broker_port, const std::string& pg) {
  return {{"station_id", kStationId},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", db_path},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}, {"time_scale", 0}}},
          {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}},
          {"mqtt",
           {{"url", "mqtt://127.0.0.1:" + std::to_string(broker_port)},
            {"topic_prefix", "plant/eol"},
            {"reconnect_s", 0.2}}},
          {"central",
           {{"postgres", pg},
            {"batch", 50},
            {"retry_min_s", 0.1},
            {"retry_max_s", 0.5},
            {"connect_timeout_s", 2}}}};
}

class PlantEndToEndTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (const std::string why = PostgresServer::Available(); !why.empty()) GTEST_SKIP() << why;
    ASSERT_GT(broker_port_, 0);
    const int pg_port = FreePort();
    ASSERT_GT(pg_port, 0);
    server_ = std::make_unique<PostgresServer>(pg_port);
    ASSERT_EQ(server_->Start(), "");
    ASSERT_TRUE(broker_.Start());
    mes_ = std::make_unique<ChildProcess>(eol::testing::MesArgv(broker_port_, "plant/eol/#"));
    ASSERT_TRUE(eol::testing::WaitSubscribed(*mes_, 20s))
        << "the MES (python3-paho-mqtt) did not subscribe: " << mes_->output();
  }
  void TearDown() override {
    mes_.reset();
    broker_.Stop();
  }

  // Runs kPerPhase tests E2E-<n> on `station`: each is stored (non-zero id, its serial) within
  // kMaxTestS, whatever the servers do.
  void RunPhase(Station& station) {
    for (int i = 0; i < kPerPhase; ++i) {
      const std::string serial = "E2E-" + std::to_string(returned_.size() + 1);
      const auto t0 = Clock::now();
      const db::TestRecord r = station.RunTest(serial);
      const double took = SecondsSince(t0);
      slowest_test_s_ = std::max(slowest_test_s_, took);
      ASSERT_NE(r.id, 0) << serial << " was not stored";
      EXPECT_EQ(r.serial, serial);
      EXPECT_LT(took, kMaxTestS) << serial << " waited on a server";
      returned_.push_back(r.id);
    }
  }

  std::unique_ptr<Station> MakeStation() {
    auto s = std::make_unique<Station>(ParseStationConfig(
        StationJson(db_path(), broker_port_, server_->url()), "plant_end_to_end_test", ""));
    s->StartMqtt();
    s->StartCentral();
    return s;
  }

  std::string db_path() const { return dir_ / "e2e.sqlite"; }

  TempDir dir_;
  const int broker_port_ = FreePort();
  MosquittoBroker broker_{dir_.path(), broker_port_};
  std::unique_ptr<PostgresServer> server_;
  std::unique_ptr<ChildProcess> mes_;
  std::vector<std::int64_t> returned_;  // ids RunTest returned, in order
  double slowest_test_s_ = 0;
};

TEST_F(PlantEndToEndTest, BrokerDatabaseAndStationRestartedMidRunEveryResultArrivesOnce) {
  auto station = MakeStation();
  auto outbox = db::Store::Open(db_path(), db::Store::Role::kReader);
  const auto pending = [&](const char* consumer) { return outbox->OutboxPending(consumer); };

  // Online: the consumers follow; the outage below comes while they may still be sending.
  ASSERT_NO_FATAL_FAILURE(RunPhase(*station));

  // Both servers go away mid-run; the station tests on, is restarted, tests on.
  broker_.Stop();
  server_->StopImmediate();
  ASSERT_NO_FATAL_FAILURE(RunPhase(*station));
  station.reset();
  station = MakeStation();
  ASSERT_NO_FATAL_FAILURE(RunPhase(*station));
  const std::int64_t backlog_mqtt = pending("mqtt");
  const std::int64_t backlog_central = pending("central");
  EXPECT_GE(backlog_mqtt, 2 * kPerPhase) << "the outage's tests wait in the outbox for MQTT";
  EXPECT_GE(backlog_central, 2 * kPerPhase) << "the outage's tests wait for the central record";

  // Both return: the backlogs replay, each timed from when its server runs again.
  auto drain = WatchDrain(db_path(), kDrainTimeout);
  ASSERT_TRUE(broker_.Start());
  const auto broker_back = Clock::now();
  ASSERT_EQ(server_->Start(), "");
  const auto central_back = Clock::now();
  const auto drained = drain.get();
  ASSERT_EQ(drained.size(), 2u) << "after the outage: mqtt " << pending("mqtt") << ", central "
                                << pending("central")
                                << " records left\nbroker: " << broker_.output();
  const double replay_mqtt_s =
      std::chrono::duration<double>(drained.at("mqtt") - broker_back).count();
  const double replay_central_s =
      std::chrono::duration<double>(drained.at("central") - central_back).count();

  // The run goes on online, and the consumers catch up.
  ASSERT_NO_FATAL_FAILURE(RunPhase(*station));
  ASSERT_TRUE(
      WaitUntil([&] { return pending("mqtt") == 0 && pending("central") == 0; }, kDrainTimeout))
      << "at the end: mqtt " << pending("mqtt") << ", central " << pending("central") << " left";
  station.reset();

  // The station's SQLite holds each test RunTest returned, once (a restart added nothing).
  const std::set<std::int64_t> ids = eol::testing::StationIds(db_path());
  ASSERT_EQ(ids, std::set<std::int64_t>(returned_.begin(), returned_.end()));

  // Central: every test id once, and nothing else.
  const auto counts = eol::testing::CentralCounts(server_->url());
  for (const std::int64_t id : ids) {
    const auto it = counts.find({kStationId, id});
    if (it == counts.end())
      ADD_FAILURE() << "test " << id << " is not in the central record";
    else
      EXPECT_EQ(it->second, 1) << "test " << id << " is in the central record " << it->second
                               << " times";
  }
  EXPECT_EQ(counts.size(), ids.size()) << "the central record holds rows the station does not";

  // MQTT: every test id at the MES, first arrivals in store order.
  std::vector<std::int64_t> stored_order;
  for (const db::OutboxEntry& e : outbox->OutboxAfterCursor("nobody", 10000))
    stored_order.push_back(e.test_id);
  int duplicates = 0;
  std::vector<std::int64_t> received;
  WaitUntil(
      [&] {
        received =
            eol::testing::ResultIds(eol::testing::Messages(*mes_), kResultTopic, &duplicates);
        return received.size() >= ids.size();
      },
      kDrainTimeout);
  EXPECT_EQ(received, stored_order) << "lost, reordered or foreign results at the MES";

  std::cout << "[ figures  ] " << returned_.size() << " tests (" << kPerPhase << " online, "
            << 2 * kPerPhase << " with both servers down and a station restart between them, "
            << kPerPhase << " after); slowest test " << slowest_test_s_
            << " s; backlog at the return: mqtt " << backlog_mqtt << ", central " << backlog_central
            << "; replayed after its server's return in: mqtt " << replay_mqtt_s << " s, central "
            << replay_central_s << " s; central rows " << counts.size()
            << " (each once); MQTT results " << received.size() << " distinct, " << duplicates
            << " duplicate(s)\n";
}

}  // namespace
}  // namespace eol::station
