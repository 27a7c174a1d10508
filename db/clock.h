// UTC timestamps in the one format the store and the records use:
// "YYYY-MM-DDThh:mm:ss.mmmZ" (ISO 8601, millisecond precision, always UTC, 'Z' suffix).
// Fixed width, so string order is time order. Independent of the locale and the TZ setting.
#pragma once

#include <chrono>
#include <optional>
#include <string>

namespace eol::db {

// `t` truncated (towards the past) to the millisecond.
std::string UtcIso8601(std::chrono::system_clock::time_point t);
std::string UtcNowIso8601();

// An ISO 8601 time as a client writes it, normalised to the store's format so that string
// comparison is time comparison:
//   YYYY-MM-DD                                   midnight UTC of that day
//   YYYY-MM-DDThh:mm[:ss[.f...]](Z|+hh:mm|-hh:mm|+hhmm|-hhmm)
// A time of day needs its offset (the station's time zone is never assumed); a space stands
// for '+' in the offset, as an unencoded '+' in a URL query arrives as a space. Fractions
// beyond milliseconds are truncated. nullopt with the reason in *why for anything else
// (a missing offset, month 13, February 30, hour 24, ...).
std::optional<std::string> NormaliseIso8601(const std::string& text, std::string* why);

}  // namespace eol::db
