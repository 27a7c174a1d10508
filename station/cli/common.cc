#include "station/cli/common.h"

#include <cmath>
#include <cstdio>
#include <iostream>
#include <stdexcept>

#include "db/clock.h"

namespace eol::station::cli {
void RunGuarded(const std::string& name, const std::function<int()>& body) {
  int code = 0;
  try {
    code = body();
  } catch (const std::exception& e) {
    std::cerr << "eol " << name << ": " << e.what() << std::endl;
    throw CLI::RuntimeError(2);
  }
  if (code != 0) throw CLI::RuntimeError(code);
}

std::string IsoOption(const std::string& option, const std::string& value) {
  std::string why;
  const auto t = db::NormaliseIso8601(value, &why);
  if (!t) throw std::runtime_error(option + ": " + why);
  return *t;
}

namespace {

// 1000000 as such, 0.99, 1e+12: whole numbers below 1e9 in full, others with %g.
std::string Short(double v) {
  char buf[32];
  if (v == std::trunc(v) && std::abs(v) < 1e9)
    std::snprintf(buf, sizeof buf, "%.0f", v);
  else
    std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// A number check: `ok` decides, `rule` is what the error says ("from 2 to 100"), `help` what
// the help shows after the option's type ("INT:in [2, 100]").
CLI::Validator NumberCheck(std::function<bool(double)> ok, const std::string& rule,
                           const std::string& help) {
  return CLI::Validator(
      [ok = std::move(ok), rule](std::string& input) -> std::string {
        double v = 0.0;
        std::size_t used = 0;
        try {
          v = std::stod(input, &used);
        } catch (const std::exception&) {
          used = 0;
        }
        if (used == 0 || used != input.size() || !std::isfinite(v))
          return "'" + input + "' is not a finite number";
        if (!ok(v)) return input + " is out of range: " + rule;
        return std::string();
      },
      help);
}

}  // namespace

CLI::Validator Between(double lo, double hi) {
  return NumberCheck([lo, hi](double v) { return v >= lo && v <= hi; },
                     "from " + Short(lo) + " to " + Short(hi),
                     "in [" + Short(lo) + ", " + Short(hi) + "]");
}

CLI::Validator Positive() {
  return NumberCheck([](double v) { return v > 0.0; }, "must be > 0", "> 0");
}

CLI::Validator NonNegative() {
  return NumberCheck([](double v) { return v >= 0.0; }, "must be >= 0", ">= 0");
}

}  // namespace eol::station::cli
