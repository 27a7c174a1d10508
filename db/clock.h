// UTC timestamps in the one format the store and the records use:
// "YYYY-MM-DDThh:mm:ss.mmmZ" (ISO 8601, millisecond precision, always UTC, 'Z' suffix).
// Fixed width, so string order is time order. Independent of the locale and the TZ setting.
#pragma once

#include <chrono>
#include <string>

namespace eol::db {

// `t` truncated (towards the past) to the millisecond.
std::string UtcIso8601(std::chrono::system_clock::time_point t);
std::string UtcNowIso8601();

}  // namespace eol::db
