#include "station/config.h"

#include <filesystem>

#include "drivers/io/json_config.h"
#include "station/serial_number.h"

namespace eol::station {
namespace {

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

StationConfig ParseStationConfig(const nlohmann::json& j, const std::string& source,
                                 const std::string& base_dir) {
  using io::JsonObject;
  try {
    const JsonObject root(j, "");
    StationConfig c;
    c.station_id = root.String("station_id", c.station_id);
    c.recipe_path = Resolve(base_dir, root.RequiredString("recipe"));
    c.db_path = Resolve(base_dir, root.RequiredString("db"));
    if (auto http = root.OptionalObject("http")) {
      c.http_listen = http->String("listen", c.http_listen);
      c.http_port = http->Integer("port", c.http_port);
      http->Require(c.http_port >= 0 && c.http_port <= 65535, "port", "must be in [0, 65535]");
      if (http->Has("tokens")) {
        const nlohmann::json& list = http->Raw("tokens");
        if (!list.is_array()) throw io::ConfigError(http->PathOf("tokens") + ": must be an array");
        for (std::size_t i = 0; i < list.size(); ++i) {
          const JsonObject t(list[i], http->PathOf("tokens") + "/" + std::to_string(i));
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
      http->RejectUnknown();
    }
    if (auto s = root.OptionalObject("safety")) {
      c.safety.watchdog_period_ms = s->Number("watchdog_period_ms", c.safety.watchdog_period_ms);
      c.safety.heartbeat_timeout_ms =
          s->Number("heartbeat_timeout_ms", c.safety.heartbeat_timeout_ms);
      c.safety.poll_period_ms = s->Number("poll_period_ms", c.safety.poll_period_ms);
      s->Require(c.safety.watchdog_period_ms >= 1 && c.safety.watchdog_period_ms <= 50,
                 "watchdog_period_ms", "must be in [1, 50] ms (the reaction target is 50 ms)");
      s->Require(c.safety.heartbeat_timeout_ms >= 600, "heartbeat_timeout_ms",
                 "must be at least 600 ms (the heartbeat increments every 500 ms)");
      s->Require(c.safety.poll_period_ms >= 1 && c.safety.poll_period_ms <= 500, "poll_period_ms",
                 "must be in [1, 500] ms");
      s->RejectUnknown();
    }
    c.serial_from_stdin = root.Bool("serial_from_stdin", false);
    if (auto sc = root.OptionalObject("self_check")) {
      SelfCheckConfig& k = c.self_check;
      k.good_master = sc->RequiredString("good_master");
      k.limit_master = sc->RequiredString("limit_master");
      k.every_n_tests = sc->Integer("every_n_tests", k.every_n_tests);
      k.every_hours = sc->Number("every_hours", k.every_hours);
      std::string why;
      sc->Require(ValidSerial(k.good_master, &why), "good_master", why);
      sc->Require(ValidSerial(k.limit_master, &why), "limit_master", why);
      sc->Require(k.limit_master != k.good_master, "limit_master",
                  "must differ from good_master (two different parts)");
      sc->Require(k.every_n_tests >= 0 && k.every_n_tests <= 100000, "every_n_tests",
                  "must be in [0, 100000] (0: no count limit)");
      sc->Require(k.every_hours >= 0 && k.every_hours <= 744, "every_hours",
                  "must be in [0, 744] h (0: no time limit)");
      sc->RejectUnknown();
    }
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
