#include "analysis/frf.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace eol::analysis {

const char* ToString(Quantity q) {
  switch (q) {
    case Quantity::kImpedanceOhm:
      return "impedance_ohm";
    case Quantity::kMobility:
      return "mobility_rad_per_s_per_a";
  }
  return "unknown";
}

bool Frf::Validate(std::string* why) const {
  auto fail = [&](const std::string& msg) {
    if (why) *why = msg;
    return false;
  };
  if (freq_hz.empty()) return fail("frequency response has no lines");
  if (value.size() != freq_hz.size())
    return fail("frequency response has " + std::to_string(freq_hz.size()) + " frequencies but " +
                std::to_string(value.size()) + " values");
  if (!sigma.empty() && sigma.size() != freq_hz.size())
    return fail("frequency response has " + std::to_string(freq_hz.size()) + " frequencies but " +
                std::to_string(sigma.size()) + " sigmas");
  for (std::size_t k = 0; k < freq_hz.size(); ++k) {
    std::ostringstream where;
    where << "line " << k << " (" << freq_hz[k] << " Hz)";
    if (!std::isfinite(freq_hz[k]) || freq_hz[k] <= 0.0)
      return fail(where.str() + ": frequency must be finite and positive");
    if (k > 0 && !(freq_hz[k] > freq_hz[k - 1]))
      return fail(where.str() + ": frequencies must increase strictly");
    if (!std::isfinite(value[k].real()) || !std::isfinite(value[k].imag()))
      return fail(where.str() + ": value is not finite");
    if (!sigma.empty() && (!std::isfinite(sigma[k]) || sigma[k] <= 0.0))
      return fail(where.str() + ": sigma must be finite and positive");
  }
  return true;
}

Frf CombineIndependent(const Frf& a, const Frf& b) {
  std::string why;
  if (!a.Validate(&why)) throw std::invalid_argument("first estimate: " + why);
  if (!b.Validate(&why)) throw std::invalid_argument("second estimate: " + why);
  if (!a.has_sigma() || !b.has_sigma())
    throw std::invalid_argument("both estimates need a sigma per line to be combined");
  if (a.quantity != b.quantity)
    throw std::invalid_argument("the estimates are of other quantities");
  if (a.freq_hz != b.freq_hz)
    throw std::invalid_argument("the estimates are on other lines (" + std::to_string(a.size()) +
                                " and " + std::to_string(b.size()) + " lines)");
  Frf c = a;
  c.method = a.method + "+" + b.method;
  for (std::size_t k = 0; k < a.size(); ++k) {
    const double wa = 1.0 / (a.sigma[k] * a.sigma[k]);
    const double wb = 1.0 / (b.sigma[k] * b.sigma[k]);
    c.value[k] = (a.value[k] * wa + b.value[k] * wb) / (wa + wb);
    c.sigma[k] = 1.0 / std::sqrt(wa + wb);
  }
  return c;
}

}  // namespace eol::analysis
