// Results to the plant's MES over MQTT (libmosquitto, MQTT 3.1.1), from the store's outbox.
//
// Topics (prefix and station id from the config):
//   <prefix>/<station_id>/result   every stored record, QoS 1, not retained, in store order:
//                                  the record's JSON (db/test_record.h) without curves; its
//                                  "station_id" and "id" (the test id) are the idempotency
//                                  key: a record can arrive twice (QoS 1: a broker that took it
//                                  but whose acknowledgement was lost), never out of order and
//                                  never not at all.
//   <prefix>/<station_id>/status   retained: {"station_id", "online": true, "state", "at"} on
//                                  connecting and at each change of the sequencer's state; the
//                                  last will, and the message of a clean stop, is the plain
//                                  text "offline".
//
// Transport: plain TCP for mqtt://, TLS for mqtts:// (MqttTls: the broker's certificate is
// checked against ca_file or the system's CAs, and its host name unless insecure; a client
// certificate when the broker asks for one).
//
// Delivery: one thread reads the outbox (db/store.h) after the cursor "mqtt", publishes one
// record at a time and advances the cursor only when the broker has acknowledged it
// (PUBACK), so a broker outage of any length, or a station restart, loses nothing and
// replays in order. The test never waits for it: the record is stored first, whatever the
// broker does. While the broker cannot be reached it tries again every reconnect_s, logging
// the first failure of an outage and the recovery.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "station/daemon/plant_urls.h"  // ParseMqttUrl

struct mosquitto;

namespace eol::station {

// TLS towards the broker (libmosquitto's mosquitto_tls_set over OpenSSL), on with an
// "mqtts://" URL. Paths are absolute once the config is parsed (relative ones are relative to
// the config file), and each named file was readable then.
struct MqttTls {
  std::string ca_file;    // PEM CA certificate(s) the broker's certificate must chain to;
                          // empty: the system's CA directory /etc/ssl/certs
  std::string cert_file;  // client certificate (PEM), with key_file, when the broker asks
  std::string key_file;   // its private key (PEM, unencrypted)
  bool insecure = false;  // true: do not check the broker's host name against its
                          // certificate (the chain is still checked). Test rigs only.
};

struct MqttConfig {
  std::string host;            // from "url": "mqtt://host:port" or "mqtts://host:port"
  int port = 1883;             // 8883 by default for mqtts://
  std::optional<MqttTls> tls;  // on for mqtts://
  std::string topic_prefix = "plant/eol";
  std::string client_id;  // empty: "eol-<station_id>"
  std::string username;   // empty: no authentication
  std::string password;
  int keepalive_s = 30;
  double reconnect_s = 1.0;  // pause between attempts while the broker is away
};

class MqttPublisher {
 public:
  // `db_path`: the station's store (its own connection); `state`: the sequencer's state name
  // for the status topic (StatusBoard::Snapshot()["state"]).
  MqttPublisher(MqttConfig config, std::string station_id, std::string db_path,
                std::function<std::string()> state);
  ~MqttPublisher();  // Stop()
  MqttPublisher(const MqttPublisher&) = delete;
  MqttPublisher& operator=(const MqttPublisher&) = delete;

  void Start();
  // Publishes "offline" (retained) when connected, disconnects and joins. Idempotent.
  void Stop();

  std::string result_topic() const;
  std::string status_topic() const;
  // Records acknowledged by the broker since Start.
  std::uint64_t published() const { return published_.load(); }
  bool connected() const { return connected_.load(); }

 private:
  void Run();
  bool Connect();
  void PublishStatus(const std::string& payload);
  void Pump();  // one loop step: maybe publish the next record, process the network

  static void OnConnect(mosquitto*, void* self, int rc);
  static void OnDisconnect(mosquitto*, void* self, int rc);
  static void OnPublish(mosquitto*, void* self, int mid);

  const MqttConfig config_;
  const std::string station_id_;
  const std::string db_path_;
  const std::function<std::string()> state_;
  const std::string where_;  // "mqtt://host:port" for messages, user-info redacted (RedactUrl)
  mosquitto* mosq_ = nullptr;
  std::thread thread_;
  std::mutex mu_;
  std::condition_variable cv_;
  bool stop_ = false;
  std::atomic<bool> connected_{false};
  std::atomic<std::uint64_t> published_{0};
  // The serving thread's own (the callbacks run inside mosquitto_loop, on that thread).
  int connack_ = -1;  // -1: no CONNACK yet
  struct InFlight {
    int mid = 0;
    std::int64_t outbox_id = 0;
    bool acked = false;
  };
  std::optional<InFlight> in_flight_;
  std::string last_state_;
  bool outage_logged_ = false;
};

}  // namespace eol::station
