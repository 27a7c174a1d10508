#include "drivers/daq/calibration_file.h"

#include <cmath>

namespace eol::drivers {

nlohmann::json CalibrationToJson(const Calibration& c) {
  nlohmann::json j = {{"shunt_ohm", c.shunt_ohm},
                      {"divider_ratio", c.divider_ratio},
                      {"channel_delay_s", c.channel_delay_s},
                      {"method", c.method}};
  if (!c.date.empty()) j["date"] = c.date;
  if (c.reference_ohm > 0.0) j["reference_ohm"] = c.reference_ohm;
  return j;
}

Calibration ParseCalibration(const io::JsonObject& o) {
  Calibration c;
  c.shunt_ohm = o.Number("shunt_ohm", c.shunt_ohm);
  c.divider_ratio = o.Number("divider_ratio", c.divider_ratio);
  c.channel_delay_s = o.Number("channel_delay_s", c.channel_delay_s);
  c.method = o.String("method", c.method);
  c.date = o.String("date", "");
  c.reference_ohm = o.Number("reference_ohm", 0.0);
  if (o.Has("estimate")) (void)o.Raw("estimate");
  o.Require(c.shunt_ohm > 0.0 && std::isfinite(c.shunt_ohm), "shunt_ohm", "must be positive");
  o.Require(c.divider_ratio > 0.0 && std::isfinite(c.divider_ratio), "divider_ratio",
            "must be positive");
  o.Require(std::abs(c.channel_delay_s) < 0.01, "channel_delay_s",
            "must be within +-10 ms (a channel skew, not a latency)");
  o.Require(c.method == "nominal" || c.method == "reference_resistor", "method",
            "must be \"nominal\" or \"reference_resistor\"");
  if (c.method == "reference_resistor") {
    o.Require(!c.date.empty(), "date", "a reference_resistor calibration needs its date");
    o.Require(c.reference_ohm > 0.0, "reference_ohm",
              "a reference_resistor calibration needs the resistor it was measured with");
  }
  o.RejectUnknown();
  return c;
}

Calibration ReadCalibrationFile(const std::string& path) {
  const nlohmann::json j = io::ReadJsonFile(path);
  try {
    return ParseCalibration(io::JsonObject(j, ""));
  } catch (const io::ConfigError& e) {
    throw io::ConfigError("calibration file " + path + ": " + e.what());
  }
}

Calibration DaqCalibration(const io::JsonObject& daq, const Calibration& fallback) {
  const bool has_file = daq.Has("calibration_file");
  const bool has_inline = daq.Has("calibration");
  if (has_file && has_inline)
    throw io::ConfigError(daq.PathOf("calibration_file") +
                          ": give a calibration_file or an inline calibration, not both");
  if (has_file) {
    const std::string path = daq.RequiredString("calibration_file");
    try {
      return ReadCalibrationFile(path);
    } catch (const io::ConfigError& e) {
      throw io::ConfigError(daq.PathOf("calibration_file") + ": " + e.what());
    }
  }
  if (has_inline) return ParseCalibration(daq.Object("calibration"));
  return fallback;
}

}  // namespace eol::drivers
