// Numbers in JSON: JSON has no NaN or infinity, so an unknown (not finite) number is written
// as null and read back as NaN. Every record field list uses these two, so the rule holds for
// every stored number alike.
#pragma once

#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>

namespace eol::analysis {

inline nlohmann::json JsonNumber(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json();
}

// j[key] as a double; NaN when absent or null.
inline double NumberOrNaN(const nlohmann::json& j, const char* key) {
  const auto it = j.find(key);
  if (it == j.end() || it->is_null()) return std::numeric_limits<double>::quiet_NaN();
  return it->get<double>();
}

}  // namespace eol::analysis
