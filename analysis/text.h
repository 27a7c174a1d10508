// Small helpers shared by the analysis code's messages and search grids.
#pragma once

#include <charconv>
#include <cmath>
#include <cstdio>
#include <locale>
#include <sstream>
#include <string>
#include <vector>

namespace eol::analysis {

// A stream for human messages: classic locale (a machine's locale must never turn 1.5 into
// "1,5" in a stored record), 6 significant digits.
inline std::ostringstream MessageStream() {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(6);
  return os;
}

// v with `digits` decimals, classic locale ("390.12"), for messages and records.
inline std::string Fixed(double v, int digits) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.setf(std::ios::fixed);
  os.precision(digits);
  os << v;
  return os.str();
}

// v with `digits` significant digits, shortest form ("417.8", "0.0085", "1.2e+06"), classic
// formatting whatever the locale; "nan", "inf", "-inf" for non-finite values.
inline std::string Significant(double v, int digits) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, digits);
  return std::string(buf, r.ptr);
}

// One number in a printf format with one conversion for a double ("%+.1f", "%9.1f", "%.3g %%"),
// for tables that need widths or signs. The programs set LC_NUMERIC "C" (station/cli/main.cc,
// eol_station_main.cc), so the decimal point is '.'. Results longer than 63 characters are cut.
inline std::string Printf(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

// A fraction as a percentage with `digits` decimals: Percent(0.1234, 1) = "12.3 %".
inline std::string Percent(double fraction, int digits) {
  return Fixed(100.0 * fraction, digits) + " %";
}

// n >= 2 log-spaced points from lo to hi inclusive (lo, hi > 0); the last point is exactly hi.
inline std::vector<double> LogSpace(double lo, double hi, int n) {
  std::vector<double> v(static_cast<std::size_t>(n));
  const double step = std::log(hi / lo) / (n - 1);
  for (int i = 0; i < n; ++i) v[static_cast<std::size_t>(i)] = lo * std::exp(step * i);
  v.back() = hi;
  return v;
}

}  // namespace eol::analysis
