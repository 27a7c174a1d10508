// Which estimator turns a periodic recording into Z(f): the recipe's analysis.frf_method.
#pragma once

#include <string_view>

namespace eol::analysis {

// How Z(f) is estimated from the recorded periods:
//   kDiscardTransient  periodic_frf.h: drop the leading transient periods, average the rest
//                      (sigma from the period-to-period scatter; needs 2 periods after them);
//   kTransientLpm      transient_frf.h: keep every period, remove the start transient by the
//                      local polynomial method (sigma from the polynomial's residuals).
enum class FrfMethod { kDiscardTransient, kTransientLpm };

// "discard_transient", "transient_lpm" (the recipe's analysis.frf_method values).
const char* ToString(FrfMethod method);
// False for any other text.
bool ParseFrfMethod(std::string_view text, FrfMethod* method);

}  // namespace eol::analysis
