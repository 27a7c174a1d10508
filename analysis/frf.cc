#include "analysis/frf.h"

#include <cmath>
#include <sstream>

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

}  // namespace eol::analysis
