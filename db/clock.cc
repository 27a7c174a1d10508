#include "db/clock.h"

#include <cstdio>
#include <ctime>
#include <stdexcept>

namespace eol::db {

namespace {

// Formats a millisecond time. Not through system_clock::time_point: its nanoseconds hold only
// the years 1678 to 2262, and a client's date outside them overflowed (undefined behaviour).
std::string FormatUtc(std::chrono::sys_time<std::chrono::milliseconds> ms) {
  using std::chrono::floor;
  using std::chrono::seconds;
  // floor, not duration_cast: times before 1970 must not round towards the epoch.
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

}  // namespace

std::string UtcIso8601(std::chrono::system_clock::time_point t) {
  return FormatUtc(std::chrono::floor<std::chrono::milliseconds>(t));
}

std::string UtcNowIso8601() { return UtcIso8601(std::chrono::system_clock::now()); }

namespace {

// `n` decimal digits at text[*pos], advancing *pos; false when there are not n digits.
bool Digits(const std::string& text, std::size_t* pos, int n, int* out) {
  if (*pos + static_cast<std::size_t>(n) > text.size()) return false;
  int v = 0;
  for (int i = 0; i < n; ++i) {
    const char c = text[*pos + static_cast<std::size_t>(i)];
    if (c < '0' || c > '9') return false;
    v = v * 10 + (c - '0');
  }
  *pos += static_cast<std::size_t>(n);
  *out = v;
  return true;
}

}  // namespace

std::optional<std::string> NormaliseIso8601(const std::string& text, std::string* why) {
  using namespace std::chrono;
  auto fail = [&](const std::string& m) -> std::optional<std::string> {
    if (why) *why = "'" + text + "' is not an ISO 8601 time: " + m;
    return std::nullopt;
  };
  std::size_t p = 0;
  int y = 0, mo = 0, d = 0, h = 0, mi = 0, s = 0, ms = 0;
  if (!Digits(text, &p, 4, &y) || p >= text.size() || text[p++] != '-' ||
      !Digits(text, &p, 2, &mo) || p >= text.size() || text[p++] != '-' || !Digits(text, &p, 2, &d))
    return fail("expected YYYY-MM-DD");
  const year_month_day date{year{y}, month{static_cast<unsigned>(mo)},
                            day{static_cast<unsigned>(d)}};
  if (!date.ok()) return fail("no such date");
  sys_time<milliseconds> t = sys_days{date};
  // The store's format has four digits of year: an offset must not carry a time out of them.
  auto finish = [&](sys_time<milliseconds> utc) -> std::optional<std::string> {
    const year_month_day ymd{floor<days>(utc)};
    if (ymd.year() < year{0} || ymd.year() > year{9999})
      return fail("outside the years 0000 to 9999 in UTC");
    return FormatUtc(utc);
  };
  if (p == text.size()) return finish(t);
  if (text[p++] != 'T') return fail("expected 'T' after the date");
  if (!Digits(text, &p, 2, &h) || p >= text.size() || text[p++] != ':' || !Digits(text, &p, 2, &mi))
    return fail("expected hh:mm after 'T'");
  if (p < text.size() && text[p] == ':') {
    ++p;
    if (!Digits(text, &p, 2, &s)) return fail("expected two digits of seconds");
    if (p < text.size() && (text[p] == '.' || text[p] == ',')) {
      ++p;
      int n = 0;
      for (; p < text.size() && text[p] >= '0' && text[p] <= '9'; ++p, ++n)
        if (n < 3) ms = ms * 10 + (text[p] - '0');
      if (n == 0) return fail("expected digits after the decimal point");
      for (; n < 3; ++n) ms *= 10;
    }
  }
  if (h > 23 || mi > 59 || s > 59) return fail("hour, minute or second out of range");
  t += hours{h} + minutes{mi} + seconds{s} + milliseconds{ms};
  if (p == text.size()) return fail("a time of day needs 'Z' or an offset such as +02:00");
  if (text[p] == 'Z' && p + 1 == text.size()) return finish(t);
  const char sign = text[p] == ' ' ? '+' : text[p];
  if (sign != '+' && sign != '-') return fail("expected 'Z' or an offset such as +02:00");
  ++p;
  int oh = 0, om = 0;
  if (!Digits(text, &p, 2, &oh)) return fail("expected the offset's hours");
  if (p < text.size() && text[p] == ':') ++p;
  if (!Digits(text, &p, 2, &om) || p != text.size()) return fail("expected the offset's minutes");
  if (oh > 23 || om > 59) return fail("offset out of range");
  // Local time = UTC + offset, so UTC = local time - offset.
  const minutes offset = hours{oh} + minutes{om};
  t += sign == '+' ? -offset : offset;
  return finish(t);
}

}  // namespace eol::db
