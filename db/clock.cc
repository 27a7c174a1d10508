#include "db/clock.h"

#include <cstdio>
#include <ctime>
#include <stdexcept>

namespace eol::db {

std::string UtcIso8601(std::chrono::system_clock::time_point t) {
  using std::chrono::floor;
  using std::chrono::milliseconds;
  using std::chrono::seconds;
  // floor, not duration_cast: times before 1970 must not round towards the epoch.
  const auto ms = floor<milliseconds>(t);
  const auto s = floor<seconds>(ms);
  const int millis = static_cast<int>((ms - s).count());
  const std::time_t secs = static_cast<std::time_t>(s.time_since_epoch().count());
  std::tm tm{};
  if (gmtime_r(&secs, &tm) == nullptr)
    throw std::out_of_range("UtcIso8601: time outside the range of struct tm");
  char buf[96];  // room for any int the compiler can imagine in each field
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, millis);
  return buf;
}

std::string UtcNowIso8601() { return UtcIso8601(std::chrono::system_clock::now()); }

}  // namespace eol::db
