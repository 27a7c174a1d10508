#include "station/daemon/mqtt_publisher.h"

#include <mosquitto.h>
#include <spdlog/spdlog.h>

#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>

#include "db/clock.h"
#include "db/store.h"

namespace eol::station {
namespace {

constexpr const char* kConsumer = "mqtt";
constexpr const char* kOffline = "offline";
constexpr const char* kSystemCaDir = "/etc/ssl/certs";

void InitLibraryOnce() {
  static std::once_flag once;
  std::call_once(once, [] { mosquitto_lib_init(); });
}

}  // namespace

MqttPublisher::MqttPublisher(MqttConfig config, std::string station_id, std::string db_path,
                             std::function<std::string()> state)
    : config_(std::move(config)),
      station_id_(std::move(station_id)),
      db_path_(std::move(db_path)),
      state_(std::move(state)),
      where_(RedactUrl("mqtt://" + config_.host + ":" + std::to_string(config_.port))) {}

MqttPublisher::~MqttPublisher() { Stop(); }

std::string MqttPublisher::result_topic() const {
  return config_.topic_prefix + "/" + station_id_ + "/result";
}
std::string MqttPublisher::status_topic() const {
  return config_.topic_prefix + "/" + station_id_ + "/status";
}

void MqttPublisher::Start() {
  if (thread_.joinable()) return;
  InitLibraryOnce();
  const std::string client_id =
      config_.client_id.empty() ? "eol-" + station_id_ : config_.client_id;
  // clean_session: the outbox, not the broker's session, is what survives; a fresh session
  // after each reconnect resends from the cursor.
  mosq_ = mosquitto_new(client_id.c_str(), /*clean_session=*/true, this);
  if (mosq_ == nullptr) throw std::runtime_error("mqtt: mosquitto_new failed (out of memory)");
  const std::string& where = where_;
  const auto check = [&](int rc, const char* what) {
    if (rc == MOSQ_ERR_SUCCESS) return;
    mosquitto_destroy(mosq_);
    mosq_ = nullptr;
    throw std::runtime_error(where + ": " + what + ": " + mosquitto_strerror(rc));
  };
  check(mosquitto_will_set(mosq_, status_topic().c_str(), static_cast<int>(std::strlen(kOffline)),
                           kOffline, 1, true),
        "last will");
  if (!config_.username.empty())
    check(mosquitto_username_pw_set(mosq_, config_.username.c_str(),
                                    config_.password.empty() ? nullptr : config_.password.c_str()),
          "username");
  if (config_.tls) {
    const MqttTls& t = *config_.tls;
    const auto opt = [](const std::string& s) { return s.empty() ? nullptr : s.c_str(); };
    // Without a ca_file, the system's CA directory (libmosquitto 2.0.11 needs one of both).
    check(mosquitto_tls_set(mosq_, opt(t.ca_file), t.ca_file.empty() ? kSystemCaDir : nullptr,
                            opt(t.cert_file), opt(t.key_file), nullptr),
          "tls (ca_file, cert_file, key_file)");
    check(mosquitto_tls_insecure_set(mosq_, t.insecure), "tls (insecure)");
  }
  mosquitto_connect_callback_set(mosq_, &MqttPublisher::OnConnect);
  mosquitto_disconnect_callback_set(mosq_, &MqttPublisher::OnDisconnect);
  mosquitto_publish_callback_set(mosq_, &MqttPublisher::OnPublish);
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = false;
  }
  thread_ = std::thread([this] { Run(); });
}

void MqttPublisher::Stop() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mu_);
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
  mosquitto_destroy(mosq_);
  mosq_ = nullptr;
}

void MqttPublisher::OnConnect(mosquitto*, void* self, int rc) {
  static_cast<MqttPublisher*>(self)->connack_ = rc;
}

void MqttPublisher::OnDisconnect(mosquitto*, void* self, int) {
  static_cast<MqttPublisher*>(self)->connected_ = false;
}

void MqttPublisher::OnPublish(mosquitto*, void* self, int mid) {
  auto* p = static_cast<MqttPublisher*>(self);
  if (p->in_flight_ && p->in_flight_->mid == mid) p->in_flight_->acked = true;
}

bool MqttPublisher::Connect() {
  connack_ = -1;
  int rc = mosquitto_connect(mosq_, config_.host.c_str(), config_.port, config_.keepalive_s);
  // Wait for the broker's CONNACK (a TCP connection alone is not a session).
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(5);
  while (rc == MOSQ_ERR_SUCCESS && connack_ < 0 && std::chrono::steady_clock::now() < deadline)
    rc = mosquitto_loop(mosq_, 100, 1);
  if (rc != MOSQ_ERR_SUCCESS || connack_ != 0) {
    if (!outage_logged_)
      spdlog::warn("{}: not connected ({}); records wait in the outbox", where_,
                   rc != MOSQ_ERR_SUCCESS ? mosquitto_strerror(rc)
                   : connack_ < 0         ? "no CONNACK within 5 s"
                                          : mosquitto_connack_string(connack_));
    outage_logged_ = true;
    mosquitto_disconnect(mosq_);
    return false;
  }
  if (outage_logged_) spdlog::info("{}: connected again", where_);
  outage_logged_ = false;
  connected_ = true;
  in_flight_.reset();  // a new session: whatever was not acknowledged is sent again
  last_state_ = state_();
  PublishStatus(nlohmann::json{{"station_id", station_id_},
                               {"online", true},
                               {"state", last_state_},
                               {"at", db::UtcNowIso8601()}}
                    .dump());
  return true;
}

void MqttPublisher::PublishStatus(const std::string& payload) {
  const int rc = mosquitto_publish(mosq_, nullptr, status_topic().c_str(),
                                   static_cast<int>(payload.size()), payload.data(), 1, true);
  if (rc != MOSQ_ERR_SUCCESS)
    spdlog::warn("mqtt: status not published: {}", mosquitto_strerror(rc));
}

void MqttPublisher::Run() {
  std::unique_ptr<db::Store> store;
  try {
    store = db::Store::Open(db_path_, db::Store::Role::kReader);
  } catch (const std::exception& e) {
    spdlog::error("mqtt: cannot read the outbox: {}; nothing will be published", e.what());
    return;
  }
  const std::string topic = result_topic();
  for (;;) {
    {
      std::unique_lock<std::mutex> lock(mu_);
      if (stop_) break;
      if (!connected_) {
        lock.unlock();
        if (!Connect()) {
          lock.lock();
          cv_.wait_for(lock, std::chrono::duration<double>(config_.reconnect_s),
                       [this] { return stop_; });
          continue;
        }
      }
    }
    try {
      if (in_flight_ && in_flight_->acked) {
        store->AdvanceOutboxCursor(kConsumer, in_flight_->outbox_id);
        in_flight_.reset();
        ++published_;
      }
      if (!in_flight_) {
        const std::vector<db::OutboxEntry> next = store->OutboxAfterCursor(kConsumer, 1);
        if (!next.empty()) {
          const std::optional<db::TestRecord> record = store->Test(next[0].test_id, false);
          if (!record) {
            // Deleted since (ON DELETE CASCADE removes its row too): nothing to deliver.
            store->AdvanceOutboxCursor(kConsumer, next[0].id);
            continue;
          }
          nlohmann::json j = *record;
          j.erase("curves");
          const std::string payload =
              j.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
          int mid = 0;
          const int rc =
              mosquitto_publish(mosq_, &mid, topic.c_str(), static_cast<int>(payload.size()),
                                payload.data(), 1, false);
          if (rc == MOSQ_ERR_SUCCESS) in_flight_ = InFlight{mid, next[0].id, false};
        }
      }
      if (const std::string s = state_(); s != last_state_) {
        last_state_ = s;
        PublishStatus(nlohmann::json{{"station_id", station_id_},
                                     {"online", true},
                                     {"state", s},
                                     {"at", db::UtcNowIso8601()}}
                          .dump());
      }
    } catch (const std::exception& e) {
      spdlog::error("mqtt: outbox: {}", e.what());
    }
    // Waits for the network at most 50 ms: a record stored meanwhile goes out at the next turn.
    const int rc = mosquitto_loop(mosq_, in_flight_ ? 10 : 50, 1);
    if (rc != MOSQ_ERR_SUCCESS) {
      if (connected_) spdlog::warn("mqtt: connection lost ({})", mosquitto_strerror(rc));
      connected_ = false;
      outage_logged_ = true;
      in_flight_.reset();
    }
  }
  // An acknowledged record whose cursor write the stop overtook: written now, so that the next
  // start does not send it again.
  if (in_flight_ && in_flight_->acked) {
    try {
      store->AdvanceOutboxCursor(kConsumer, in_flight_->outbox_id);
      ++published_;
    } catch (const std::exception& e) {
      spdlog::error("mqtt: outbox: {}", e.what());
    }
  }
  if (connected_) {
    PublishStatus(kOffline);
    for (int i = 0; i < 10; ++i) mosquitto_loop(mosq_, 20, 1);  // let it leave
    mosquitto_disconnect(mosq_);
    connected_ = false;
  }
}

}  // namespace eol::station
