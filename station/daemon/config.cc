#include "station/daemon/config.h"

#include <arpa/inet.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "db/serial_number.h"
#include "drivers/io/json_config.h"
#include "station/daemon/plant_urls.h"
#include "station/daemon/reason_cause.h"
#include "station/daemon/variants.h"

namespace eol::station {
namespace {

// 127.0.0.0/8, ::1 and "localhost": addresses only this host can reach.
bool IsLoopback(const std::string& host) {
  if (host == "localhost") return true;
  in_addr v4{};
  if (inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  in6_addr v6{};
  return inet_pton(AF_INET6, host.c_str(), &v6) == 1 && IN6_IS_ADDR_LOOPBACK(&v6);
}

std::string Resolve(const std::string& base_dir, const std::string& p) {
  if (p.empty() || std::filesystem::path(p).is_absolute() || base_dir.empty()) return p;
  return (std::filesystem::path(base_dir) / p).lexically_normal().string();
}

}  // namespace

const char* ToString(Role role) {
  switch (role) {
    case Role::kOperator:
      return "operator";
    case Role::kEngineer:
      return "engineer";
  }
  return "unknown";
}

std::optional<Role> ParseRole(std::string_view text) {
  for (Role r : {Role::kOperator, Role::kEngineer})
    if (text == ToString(r)) return r;
  return std::nullopt;
}

std::string SimulationReason(const StationConfig& config) {
  std::string why;
  for (const char* part : {"fixture", "daq"}) {
    if (!config.drivers.contains(part) || !config.drivers.at(part).is_object()) continue;
    const std::string driver = config.drivers.at(part).value("driver", "");
    if (driver == "sim" || driver == "replay")
      why += (why.empty() ? "" : ", ") + std::string(part) + " driver '" + driver + "'";
  }
  return why;
}

static void ParseHttp(const io::JsonObject& http, StationConfig& c) {
  c.http_listen = http.String("listen", c.http_listen);
  c.http_port = http.Integer("port", c.http_port);
  http.Require(c.http_port >= 0 && c.http_port <= 65535, "port", "must be in [0, 65535]");
  if (http.Has("tokens")) {
    const nlohmann::json& list = http.Raw("tokens");
    if (!list.is_array()) throw io::ConfigError(http.PathOf("tokens") + ": must be an array");
    for (std::size_t i = 0; i < list.size(); ++i) {
      const io::JsonObject t(list[i], http.PathOf("tokens") + "/" + std::to_string(i));
      const std::optional<Role> role = ParseRole(t.RequiredString("role"));
      t.Require(role.has_value(), "role", "must be one of: operator, engineer");
      ApiToken token{t.RequiredString("name"), *role, t.RequiredString("token")};
      // Token values never appear in messages.
      if (token.token.size() < 16)
        throw io::ConfigError(t.PathOf("token") + ": must be at least 16 characters");
      for (const ApiToken& other : c.tokens)
        if (other.token == token.token)
          throw io::ConfigError(t.PathOf("token") + ": is used twice");
      t.RejectUnknown();
      c.tokens.push_back(token);
    }
  }
  if (http.Has("hosts")) {
    const nlohmann::json& list = http.Raw("hosts");
    const auto name_ok = [](const nlohmann::json& h) {
      if (!h.is_string()) return false;
      const std::string s = h.get<std::string>();
      return !s.empty() && s.size() <= 253 &&
             s.find_first_not_of(
                 "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ"
                 "0123456789.-[]:") == std::string::npos;
    };
    if (!list.is_array() || !std::all_of(list.begin(), list.end(), name_ok))
      throw io::ConfigError(http.PathOf("hosts") +
                            ": must be an array of host names or addresses, without a port "
                            "(\"eol-1.plant.local\", \"10.0.0.5\")");
    for (const auto& h : list) c.http_hosts.push_back(h.get<std::string>());
  }
  http.RejectUnknown();
  // Without tokens anyone who reaches the port may start tests: only this host may.
  if (c.tokens.empty() && !IsLoopback(c.http_listen))
    throw io::ConfigError(http.PathOf("listen") + ": \"" + c.http_listen +
                          "\" listens beyond this host, which needs \"tokens\" (none are "
                          "configured); listen on 127.0.0.1 or configure tokens");
}

static void ParseSafety(const io::JsonObject& s, StationConfig& c) {
  c.safety.watchdog_period_ms = s.Number("watchdog_period_ms", c.safety.watchdog_period_ms);
  c.safety.heartbeat_timeout_ms = s.Number("heartbeat_timeout_ms", c.safety.heartbeat_timeout_ms);
  c.safety.poll_period_ms = s.Number("poll_period_ms", c.safety.poll_period_ms);
  c.safety.safe_state_retry_s = s.Number("safe_state_retry_s", c.safety.safe_state_retry_s);
  c.safety.watchdog_reaction_ms = s.Number("watchdog_reaction_ms", c.safety.watchdog_reaction_ms);
  c.safety.alive_period_ms = s.Number("alive_period_ms", c.safety.alive_period_ms);
  s.Require(c.safety.watchdog_reaction_ms == 0 ||
                (c.safety.watchdog_reaction_ms >= 20 && c.safety.watchdog_reaction_ms <= 1000),
            "watchdog_reaction_ms", "must be 0 (the default) or in [20, 1000] ms");
  s.Require(c.safety.alive_period_ms >= 10 && c.safety.alive_period_ms <= 100, "alive_period_ms",
            "must be in [10, 100] ms (the controller's alive timeout is 250 ms)");
  s.Require(c.safety.watchdog_period_ms >= 1 && c.safety.watchdog_period_ms <= 50,
            "watchdog_period_ms", "must be in [1, 50] ms (the reaction target is 50 ms)");
  s.Require(c.safety.heartbeat_timeout_ms >= 600, "heartbeat_timeout_ms",
            "must be at least 600 ms (the heartbeat increments every 500 ms)");
  s.Require(c.safety.poll_period_ms >= 1 && c.safety.poll_period_ms <= 500, "poll_period_ms",
            "must be in [1, 500] ms");
  s.Require(c.safety.safe_state_retry_s >= 0 && c.safety.safe_state_retry_s <= 60,
            "safe_state_retry_s", "must be in [0, 60] s");
  s.RejectUnknown();
}

static void ParseHealth(const io::JsonObject& h, StationConfig& c) {
  c.health.period_ms = h.Number("period_ms", c.health.period_ms);
  h.Require(c.health.period_ms >= 50 && c.health.period_ms <= 10000, "period_ms",
            "must be in [50, 10000] ms");
  h.RejectUnknown();
}

static void ParseSelfCheck(const io::JsonObject& sc, StationConfig& c) {
  SelfCheckConfig& k = c.self_check;
  k.good_master = sc.RequiredString("good_master");
  k.limit_master = sc.RequiredString("limit_master");
  k.every_n_tests = sc.Integer("every_n_tests", k.every_n_tests);
  k.every_hours = sc.Number("every_hours", k.every_hours);
  std::string why;
  sc.Require(db::ValidSerial(k.good_master, &why), "good_master", why);
  sc.Require(db::ValidSerial(k.limit_master, &why), "limit_master", why);
  sc.Require(k.limit_master != k.good_master, "limit_master",
             "must differ from good_master (two different parts)");
  sc.Require(k.every_n_tests >= 0 && k.every_n_tests <= 100000, "every_n_tests",
             "must be in [0, 100000] (0: no count limit)");
  sc.Require(k.every_hours >= 0 && k.every_hours <= 744, "every_hours",
             "must be in [0, 744] h (0: no time limit)");
  sc.RejectUnknown();
}

static void ParsePlc(const io::JsonObject& p, StationConfig& c) {
  plc::PlcServerSettings s;
  s.listen = p.String("listen", s.listen);
  s.port = p.Integer("port", s.port);
  s.unit_id = p.Integer("unit_id", s.unit_id);
  s.max_clients = p.Integer("max_clients", s.max_clients);
  p.Require(s.port >= 0 && s.port <= 65535, "port", "must be in [0, 65535]");
  p.Require(s.unit_id >= 1 && s.unit_id <= 247, "unit_id", "must be in [1, 247]");
  p.Require(s.max_clients >= 1 && s.max_clients <= 64, "max_clients", "must be in [1, 64]");
  const double frame_ms = p.Number("frame_deadline_ms", 1000);
  const double idle_s = p.Number("idle_timeout_s", 60);
  p.Require(frame_ms >= 10 && frame_ms <= 60000, "frame_deadline_ms", "must be in [10, 60000] ms");
  p.Require(idle_s >= 0.1 && idle_s <= 86400, "idle_timeout_s", "must be in [0.1, 86400] s");
  s.frame_deadline = std::chrono::milliseconds(std::lround(frame_ms));
  s.idle_timeout = std::chrono::milliseconds(std::lround(idle_s * 1000));
  if (p.Has("map")) s.map = plc::ParsePlcMap(p.Raw("map"), p.PathOf("map"));
  p.RejectUnknown();
  c.plc = s;
}

static void ParseMqtt(const io::JsonObject& m, const std::string& base_dir, StationConfig& c) {
  MqttConfig q;
  std::string why;
  bool tls = false;
  // Not Require: its "(got ...)" would print a password; `why` shows the URL redacted.
  if (!ParseMqttUrl(m.RequiredString("url"), &q.host, &q.port, &tls, &why))
    throw io::ConfigError(m.PathOf("url") + ": " + why);
  q.topic_prefix = m.String("topic_prefix", q.topic_prefix);
  m.Require(!q.topic_prefix.empty() && q.topic_prefix.find_first_of("#+") == std::string::npos &&
                q.topic_prefix.back() != '/',
            "topic_prefix", "must be a topic without wildcards or a trailing '/'");
  q.client_id = m.String("client_id", q.client_id);
  q.username = m.String("username", q.username);
  q.password = m.String("password", q.password);
  q.keepalive_s = m.Integer("keepalive_s", q.keepalive_s);
  q.reconnect_s = m.Number("reconnect_s", q.reconnect_s);
  m.Require(q.keepalive_s >= 5 && q.keepalive_s <= 3600, "keepalive_s", "must be in [5, 3600] s");
  m.Require(q.reconnect_s >= 0.05 && q.reconnect_s <= 600, "reconnect_s",
            "must be in [0.05, 600] s");
  if (auto t = m.OptionalObject("tls")) {
    m.Require(tls, "tls", "needs an mqtts:// url (this one is plain mqtt://)");
    MqttTls s;
    // Each named file must be readable now: a typo is a config error, not an outage.
    const auto file = [&](const std::string& key) {
      const std::string path = Resolve(base_dir, t->String(key, ""));
      if (path.empty()) return path;
      std::ifstream probe(path);
      t->Require(probe.good(), key, "cannot read the file " + path);
      return path;
    };
    s.ca_file = file("ca_file");
    s.cert_file = file("cert_file");
    s.key_file = file("key_file");
    s.insecure = t->Bool("insecure", s.insecure);
    t->Require(s.cert_file.empty() == s.key_file.empty(),
               s.cert_file.empty() ? "cert_file" : "key_file",
               "cert_file and key_file go together (a client certificate and its key)");
    t->RejectUnknown();
    q.tls = s;
  } else if (tls) {
    q.tls = MqttTls{};  // the system's CAs, host name checked
  }
  m.RejectUnknown();
  c.mqtt = q;
}

static void ParseCentral(const io::JsonObject& p, StationConfig& c) {
  central::CentralConfig q;
  q.postgres = p.RequiredString("postgres");
  // Not Require: its "(got ...)" would print the password.
  if (q.postgres.rfind("postgresql://", 0) != 0 && q.postgres.rfind("postgres://", 0) != 0)
    throw io::ConfigError(p.PathOf("postgres") +
                          ": must be a URI postgresql://user@host:port/db (got '" +
                          central::RedactUrl(q.postgres) + "')");
  q.batch = p.Integer("batch", q.batch);
  q.retry_min_s = p.Number("retry_min_s", q.retry_min_s);
  q.retry_max_s = p.Number("retry_max_s", q.retry_max_s);
  q.connect_timeout_s = p.Integer("connect_timeout_s", q.connect_timeout_s);
  p.Require(q.batch >= 1 && q.batch <= 10000, "batch", "must be in [1, 10000]");
  p.Require(q.retry_min_s >= 0.01 && q.retry_min_s <= 3600, "retry_min_s",
            "must be in [0.01, 3600] s");
  p.Require(q.retry_max_s >= q.retry_min_s && q.retry_max_s <= 3600, "retry_max_s",
            "must be in [retry_min_s, 3600] s");
  p.Require(q.connect_timeout_s >= 1 && q.connect_timeout_s <= 600, "connect_timeout_s",
            "must be in [1, 600] s");
  p.RejectUnknown();
  c.central = q;
}

StationConfig ParseStationConfig(const nlohmann::json& j, const std::string& source,
                                 const std::string& base_dir) {
  using io::JsonObject;
  try {
    const JsonObject root(j, "");
    StationConfig c;
    c.station_id = root.String("station_id", c.station_id);
    if (root.Has("variants")) {
      if (root.Has("recipe"))
        throw io::ConfigError(root.PathOf("recipe") +
                              ": give either \"recipe\" (one recipe) or \"variants\" (several, "
                              "one picked per unit), not both");
      c.variants = ParseVariants(root.Raw("variants"), root.PathOf("variants"),
                                 [&](const std::string& p) { return Resolve(base_dir, p); });
      c.recipe_path = c.variants.front().recipe_path;  // shown until the first unit
    } else {
      c.recipe_path = Resolve(base_dir, root.RequiredString("recipe"));
    }
    c.db_path = Resolve(base_dir, root.RequiredString("db"));
    c.init_store = root.Bool("init_store", false);
    c.language = root.String("language", c.language);
    root.Require(
        std::find(kPageLanguages.begin(), kPageLanguages.end(), c.language) != kPageLanguages.end(),
        "language", "must be one of: en, de, ja (a catalogue in station/web/i18n/)");
    if (auto o = root.OptionalObject("http")) ParseHttp(*o, c);
    if (auto o = root.OptionalObject("safety")) ParseSafety(*o, c);
    if (auto o = root.OptionalObject("health")) ParseHealth(*o, c);
    c.serial_from_stdin = root.Bool("serial_from_stdin", false);
    c.publish_before_release = root.Bool("publish_before_release", false);
    if (auto o = root.OptionalObject("self_check")) ParseSelfCheck(*o, c);
    // The driver sections are validated by drivers::MakeDrivers; mark them known here.
    c.drivers["fixture"] = root.Raw("fixture");
    c.drivers["daq"] = root.Raw("daq");
    // The daq's files (calibration, replayed recordings) are relative to this file too.
    if (nlohmann::json& daq = c.drivers["daq"]; daq.is_object()) {
      for (const char* key : {"calibration_file", "directory", "file"})
        if (daq.contains(key) && daq[key].is_string())
          daq[key] = Resolve(base_dir, daq[key].get<std::string>());
      if (daq.contains("files") && daq["files"].is_array())
        for (auto& f : daq["files"])
          if (f.is_string()) f = Resolve(base_dir, f.get<std::string>());
    }
    if (root.Has("sim")) c.drivers["sim"] = root.Raw("sim");
    if (auto o = root.OptionalObject("plc")) ParsePlc(*o, c);
    if (auto o = root.OptionalObject("mqtt")) ParseMqtt(*o, base_dir, c);
    if (auto o = root.OptionalObject("central")) ParseCentral(*o, c);
    root.RejectUnknown();
    return c;
  } catch (const io::ConfigError& e) {
    throw io::ConfigError("config " + source + ": " + e.what());
  }
}

StationConfig LoadStationConfig(const std::string& path) {
  const nlohmann::json j = io::ReadJsonFile(path);
  const std::string dir = std::filesystem::absolute(path).parent_path().string();
  return ParseStationConfig(j, path, dir);
}

}  // namespace eol::station
