#include "station/bench/plant_bench.h"

#include <mosquitto.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <thread>
#include <vector>

#include "db/clock.h"
#include "db/store.h"
#include "station/daemon/central/central_replicator.h"
#include "station/daemon/central/pg.h"
#include "station/daemon/mqtt_publisher.h"

namespace eol::station {
namespace {

using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

double Ms(Clock::duration d) { return std::chrono::duration<double, std::milli>(d).count(); }

Percentiles Summarise(std::vector<double> ms) {
  Percentiles p;
  if (ms.empty()) return p;
  std::sort(ms.begin(), ms.end());
  p.median_ms = ms[ms.size() / 2];
  p.p95_ms = ms[std::min(ms.size() - 1, static_cast<std::size_t>(0.95 * ms.size()))];
  p.max_ms = ms.back();
  return p;
}

db::Curve Curve400(const std::string& name, double scale) {
  db::Curve c{name, "ohm", {}, {}, {}, {}};
  for (int i = 0; i < 400; ++i) {
    c.freq_hz.push_back(50.0 + 2.0 * i);
    c.re.push_back(scale * (1.0 + 1e-3 * i));
    c.im.push_back(scale * 0.01 * i);
    c.sigma.push_back(1e-4);
  }
  return c;
}

db::TestRecord BenchRecord(const std::string& station, int n) {
  db::TestRecord r;
  r.serial = "BENCH-" + std::to_string(n);
  r.station_id = station;
  r.recipe_id = "pmsm-10pole";
  r.recipe_version = 1;
  r.recipe_hash = std::string(64, 'e');
  r.software_version = "plant-bench";
  r.started_at = r.finished_at = db::UtcNowIso8601();
  r.outcome = n % 10 == 0 ? analysis::Outcome::kFail : analysis::Outcome::kPass;
  if (r.outcome == analysis::Outcome::kFail)
    r.reasons.push_back({analysis::ReasonCode::kLimit, "resonance_f_hz 388.1 Hz below 390 Hz"});
  for (const char* name : {"resonance_f_hz", "resonance_q", "winding_r_ohm", "winding_l_h"}) {
    analysis::Measurement m;
    m.name = name;
    m.unit = "1";
    m.value = 400.0 + n;
    m.sigma = 0.5;
    m.doc = "bench measurement";
    r.measurements.push_back(m);
  }
  r.work = {"op-7", "A", "PO-4711"};
  r.curves = {Curve400("impedance", 1.0), Curve400("model", 1.0)};
  return r;
}

// The MES: a QoS 1 subscriber noting when each result (by test id) arrived.
class Subscriber {
 public:
  Subscriber(const std::string& host, int port, const std::string& topic) {
    mosq_ = mosquitto_new(("eol-plant-bench-" + std::to_string(getpid())).c_str(), true, this);
    if (mosq_ == nullptr) throw std::runtime_error("plant-bench: mosquitto_new failed");
    mosquitto_message_callback_set(mosq_, &Subscriber::OnMessage);
    const std::string where = "mqtt " + host + ":" + std::to_string(port);
    int rc = mosquitto_connect(mosq_, host.c_str(), port, 30);
    if (rc == MOSQ_ERR_SUCCESS) rc = mosquitto_subscribe(mosq_, nullptr, topic.c_str(), 1);
    if (rc == MOSQ_ERR_SUCCESS) rc = mosquitto_loop_start(mosq_);
    if (rc != MOSQ_ERR_SUCCESS) {
      mosquitto_destroy(mosq_);
      throw std::runtime_error(where + ": subscriber: " + mosquitto_strerror(rc));
    }
  }
  ~Subscriber() {
    mosquitto_disconnect(mosq_);
    mosquitto_loop_stop(mosq_, false);
    mosquitto_destroy(mosq_);
  }
  Subscriber(const Subscriber&) = delete;
  Subscriber& operator=(const Subscriber&) = delete;

  std::optional<Clock::time_point> ArrivalOf(std::int64_t id) {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = arrived_.find(id);
    if (it == arrived_.end()) return std::nullopt;
    return it->second;
  }
  std::size_t count() {
    std::lock_guard<std::mutex> lock(mu_);
    return arrived_.size();
  }

 private:
  static void OnMessage(mosquitto*, void* self, const mosquitto_message* m) {
    const auto now = Clock::now();
    const auto j =
        nlohmann::json::parse(static_cast<const char*>(m->payload),
                              static_cast<const char*>(m->payload) + m->payloadlen, nullptr, false);
    if (j.is_discarded() || !j.contains("id")) return;
    auto* s = static_cast<Subscriber*>(self);
    std::lock_guard<std::mutex> lock(s->mu_);
    s->arrived_.emplace(j["id"].get<std::int64_t>(), now);
  }
  mosquitto* mosq_ = nullptr;
  std::mutex mu_;
  std::map<std::int64_t, Clock::time_point> arrived_;
};

template <typename F>
void WaitFor(F done, std::chrono::seconds limit, const std::string& what) {
  const auto end = Clock::now() + limit;
  while (!done()) {
    if (Clock::now() > end)
      throw std::runtime_error("plant-bench: " + what + " not done within " +
                               std::to_string(limit.count()) + " s");
    std::this_thread::sleep_for(1ms);
  }
}

}  // namespace

PlantBenchSummary RunPlantBench(const PlantBenchOptions& o) {
  PlantBenchSummary s;
  s.station_id = "bench-" + std::to_string(getpid()) + "-" +
                 std::to_string(std::chrono::system_clock::now().time_since_epoch().count());
  s.online = o.online;
  s.backlog = o.backlog;
  const std::string db_path = o.work_dir + "/" + s.station_id + ".sqlite";
  auto store = db::Store::Open(db_path);
  {
    const db::TestRecord r = BenchRecord(s.station_id, 0);
    nlohmann::json j = r;
    const std::size_t full = j.dump().size();
    j.erase("curves");
    s.record_json_bytes = std::to_string(j.dump().size()) + " / " + std::to_string(full);
  }
  MqttConfig mq;
  mq.host = o.mqtt_host;
  mq.port = o.mqtt_port;
  mq.reconnect_s = 0.2;
  central::CentralConfig cc;
  cc.postgres = o.central;
  Subscriber mes(o.mqtt_host, o.mqtt_port, mq.topic_prefix + "/" + s.station_id + "/result");
  auto pg = central::PgConnection::Connect(o.central, 10, "plant-bench");
  const auto idle = [] { return std::string("idle"); };

  // Delays, one record at a time, with both consumers running as in the station.
  {
    MqttPublisher publisher(mq, s.station_id, db_path, idle);
    central::CentralReplicator replicator(cc, db_path, s.station_id);
    publisher.Start();
    replicator.Start();
    WaitFor([&] { return publisher.connected(); }, 30s, "connecting to the broker");
    std::vector<double> to_mqtt, to_pg;
    for (int i = 1; i <= o.online; ++i) {
      db::TestRecord r = BenchRecord(s.station_id, i);
      store->Insert(r);  // durable when it returns: the verdict may be published from here
      const auto stored = Clock::now();
      std::optional<Clock::time_point> row_at;
      WaitFor(
          [&] {
            if (!row_at) {
              try {
                if (pg->Exec("SELECT 1 FROM tests WHERE station_id = $1 AND test_id = $2::bigint",
                             {s.station_id, std::to_string(r.id)}, "look for the row")
                        .rows() == 1)
                  row_at = Clock::now();
              } catch (const central::PgError&) {
                // the table is made by the replicator's first connection
              }
            }
            return row_at && mes.ArrivalOf(r.id);
          },
          60s, "record " + std::to_string(i) + " reaching MQTT and PostgreSQL");
      to_mqtt.push_back(Ms(*mes.ArrivalOf(r.id) - stored));
      to_pg.push_back(Ms(*row_at - stored));
      std::this_thread::sleep_for(std::chrono::duration<double>(o.gap_s));
    }
    s.stored_to_mqtt = Summarise(to_mqtt);
    s.stored_to_postgres = Summarise(to_pg);
  }

  // A backlog written while both were stopped (an outage), then each alone.
  for (int i = 0; i < o.backlog; ++i) {
    db::TestRecord r = BenchRecord(s.station_id, o.online + 1 + i);
    store->Insert(r);
  }
  const std::size_t want = static_cast<std::size_t>(o.online + o.backlog);
  {
    MqttPublisher publisher(mq, s.station_id, db_path, idle);
    const auto t0 = Clock::now();
    publisher.Start();
    WaitFor([&] { return store->OutboxPending("mqtt") == 0; }, 600s, "the MQTT replay");
    s.mqtt_replay_s = Ms(Clock::now() - t0) / 1e3;
    WaitFor([&] { return mes.count() >= want; }, 120s, "the subscriber receiving the replay");
    s.mqtt_all_received_s = Ms(Clock::now() - t0) / 1e3;
  }
  {
    central::CentralReplicator replicator(cc, db_path, s.station_id);
    const auto t0 = Clock::now();
    replicator.Start();
    WaitFor([&] { return store->OutboxPending("central") == 0; }, 600s, "the central replay");
    s.central_replay_s = Ms(Clock::now() - t0) / 1e3;
  }
  s.mqtt_replay_per_s = o.backlog / s.mqtt_replay_s;
  s.central_per_s = o.backlog / s.central_replay_s;
  const auto rows = pg->Exec("SELECT count(*) FROM tests WHERE station_id = $1", {s.station_id},
                             "count the rows");
  if (std::stoul(rows.Text(0, 0)) != want)
    throw std::runtime_error("plant-bench: " + rows.Text(0, 0) + " central rows, expected " +
                             std::to_string(want));
  std::error_code ec;
  for (const char* suffix : {"", "-wal", "-shm", ".lock"})
    std::filesystem::remove(db_path + suffix, ec);
  return s;
}

nlohmann::json ToJson(const PlantBenchSummary& s) {
  const auto p = [](const Percentiles& x) {
    return nlohmann::json{{"median_ms", x.median_ms}, {"p95_ms", x.p95_ms}, {"max_ms", x.max_ms}};
  };
  return {{"station_id", s.station_id},
          {"online_records", s.online},
          {"stored_to_mqtt", p(s.stored_to_mqtt)},
          {"stored_to_postgres", p(s.stored_to_postgres)},
          {"backlog_records", s.backlog},
          {"mqtt_replay_s", s.mqtt_replay_s},
          {"mqtt_replay_records_per_s", s.mqtt_replay_per_s},
          {"mqtt_all_received_s", s.mqtt_all_received_s},
          {"central_replay_s", s.central_replay_s},
          {"central_insert_records_per_s", s.central_per_s},
          {"record_json_bytes_without_with_curves", s.record_json_bytes}};
}

}  // namespace eol::station
