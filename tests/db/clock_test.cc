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

TEST(ClockTest, NormalisesIso8601WithOffsetsToUtc) {
  auto n = [](const std::string& text) { return NormaliseIso8601(text, nullptr).value_or("-"); };
  EXPECT_EQ(n("2026-03-01"), "2026-03-01T00:00:00.000Z");
  EXPECT_EQ(n("2026-03-01T10:15Z"), "2026-03-01T10:15:00.000Z");
  EXPECT_EQ(n("2026-03-01T10:15:30.123456Z"), "2026-03-01T10:15:30.123Z");
  EXPECT_EQ(n("2026-03-01T10:15:30.5Z"), "2026-03-01T10:15:30.500Z");
  // Offsets move the instant: 01:30 at +02:00 is the previous day in UTC.
  EXPECT_EQ(n("2026-03-01T01:30:00+02:00"), "2026-02-28T23:30:00.000Z");
  EXPECT_EQ(n("2026-03-01T01:30:00+0200"), "2026-02-28T23:30:00.000Z");
  EXPECT_EQ(n("2026-03-01T01:30:00 02:00"), "2026-02-28T23:30:00.000Z");  // '+' from a URL
  EXPECT_EQ(n("2026-02-28T23:30:00-05:30"), "2026-03-01T05:00:00.000Z");
  EXPECT_EQ(n("2024-02-29"), "2024-02-29T00:00:00.000Z");
}

TEST(ClockTest, RefusesWhatIsNotAnIso8601TimeNamingWhy) {
  for (const std::string bad :
       {"", "notadate", "2026-13-01", "2025-02-29", "2026-02-30", "2026-03-01T24:00Z",
        "2026-03-01T10:60Z", "2026-03-01T10:15", "2026-03-01T10:15:00", "2026-03-01T10:15+2",
        "2026-03-01T10:15Zjunk", "2026-03-01 10:15Z", "1e12", "2026-3-1", "2026-03-01T10:15:00.Z",
        "2026-03-01T10:15+24:00"}) {
    std::string why;
    EXPECT_EQ(NormaliseIso8601(bad, &why), std::nullopt) << bad;
    EXPECT_NE(why.find("is not an ISO 8601 time"), std::string::npos) << bad << ": " << why;
  }
  std::string why;
  NormaliseIso8601("2026-03-01T10:15", &why);
  EXPECT_EQ(why,
            "'2026-03-01T10:15' is not an ISO 8601 time: a time of day needs 'Z' or an offset "
            "such as +02:00");
}

// Found by tests/fuzz/http_body_fuzzer.cc (?from=1026-11-26T10:00:00.123+01:00): a year outside
// 1678..2262 overflowed system_clock's nanoseconds (undefined behaviour, a wrong time).
TEST(ClockTest, NormalisesEveryFourDigitYearAndRefusesOffsetsBeyondThem) {
  auto n = [](const std::string& text) { return NormaliseIso8601(text, nullptr).value_or("-"); };
  EXPECT_EQ(n("1026-11-26T10:00:00.123+01:00"), "1026-11-26T09:00:00.123Z");
  EXPECT_EQ(n("0000-01-01"), "0000-01-01T00:00:00.000Z");
  EXPECT_EQ(n("9999-12-31T23:59:59.999Z"), "9999-12-31T23:59:59.999Z");
  EXPECT_EQ(n("1600-02-29T12:00-12:00"), "1600-03-01T00:00:00.000Z");
  for (const std::string out : {"0000-01-01T00:30+01:00", "9999-12-31T23:30-01:00"}) {
    std::string why;
    EXPECT_EQ(NormaliseIso8601(out, &why), std::nullopt) << out;
    EXPECT_EQ(why, "'" + out + "' is not an ISO 8601 time: outside the years 0000 to 9999 in UTC");
  }
}

}  // namespace
}  // namespace eol::db
