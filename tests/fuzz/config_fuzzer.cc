// station::ParseStationConfig (station/daemon/config.h) on JSON text as LoadStationConfig gives it:
// a StationConfig or io::ConfigError. Whole numbers must be kept as given and the safety
// options stay in their documented ranges.
#include "drivers/io/json_config.h"
#include "station/daemon/config.h"
#include "tests/fuzz/json_check.h"

namespace {

// The config's integers, at the JSON pointers they are read from.
nlohmann::json Integers(const eol::station::StationConfig& c) {
  nlohmann::json j;
  j["http"]["port"] = c.http_port;
  j["self_check"]["every_n_tests"] = c.self_check.every_n_tests;
  return j;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const nlohmann::json j = eol::io::ParseJsonText(text, "fuzz.json");
    const eol::station::StationConfig c =
        eol::station::ParseStationConfig(j, "fuzz.json", "/etc/eol");
    eol::fuzz::CheckIntegersKept(j, Integers(c), "ParseStationConfig");
    if (c.http_port < 0 || c.http_port > 65535)
      eol::fuzz::Finding("ParseStationConfig: port " + std::to_string(c.http_port));
    if (!(c.safety.watchdog_period_ms >= 1 && c.safety.heartbeat_timeout_ms >= 600 &&
          c.safety.poll_period_ms >= 1 && c.safety.safe_state_retry_s >= 0))
      eol::fuzz::Finding("ParseStationConfig: safety options out of their documented ranges");
  } catch (const eol::io::ConfigError&) {
  } catch (...) {
    eol::fuzz::FailOnException("ParseStationConfig");
  }
  return 0;
}
