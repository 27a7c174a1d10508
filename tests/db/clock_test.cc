// db/clock.h: the store's one timestamp format, independent of the time zone.
#include "db/clock.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdlib>
#include <ctime>
#include <regex>

namespace eol::db {
namespace {

using std::chrono::milliseconds;
using std::chrono::system_clock;

system_clock::time_point AtMs(long long ms) { return system_clock::time_point(milliseconds(ms)); }

TEST(ClockTest, FormatsKnownInstants) {
  EXPECT_EQ(UtcIso8601(AtMs(0)), "1970-01-01T00:00:00.000Z");
  EXPECT_EQ(UtcIso8601(AtMs(1'700'000'000'123)), "2023-11-14T22:13:20.123Z");
  EXPECT_EQ(UtcIso8601(AtMs(951'782'400'000)), "2000-02-29T00:00:00.000Z");  // leap day
  // Before the epoch, truncation is towards the past, not towards 1970.
  EXPECT_EQ(UtcIso8601(AtMs(-1)), "1969-12-31T23:59:59.999Z");
  // Sub-millisecond parts are dropped, never rounded up.
  EXPECT_EQ(UtcIso8601(AtMs(1'700'000'000'123) + std::chrono::microseconds(999)),
            "2023-11-14T22:13:20.123Z");
}

TEST(ClockTest, IgnoresTheTimeZone) {
  const char* old = std::getenv("TZ");
  const std::string saved = old != nullptr ? old : "";
  setenv("TZ", "America/St_Johns", 1);  // UTC-3:30, with daylight saving
  tzset();
  const std::string s = UtcIso8601(AtMs(1'700'000'000'123));
  if (old != nullptr)
    setenv("TZ", saved.c_str(), 1);
  else
    unsetenv("TZ");
  tzset();
  EXPECT_EQ(s, "2023-11-14T22:13:20.123Z");
}

TEST(ClockTest, NowHasTheStoreFormat) {
  const std::string before = UtcIso8601(system_clock::now());
  const std::string now = UtcNowIso8601();
  EXPECT_TRUE(std::regex_match(now, std::regex(R"(\d{4}-\d\d-\d\dT\d\d:\d\d:\d\d\.\d{3}Z)")))
      << now;
  EXPECT_LE(before, now);  // fixed width: string order is time order
}

}  // namespace
}  // namespace eol::db
