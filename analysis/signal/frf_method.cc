#include "analysis/signal/frf_method.h"

namespace eol::analysis {

const char* ToString(FrfMethod method) {
  switch (method) {
    case FrfMethod::kDiscardTransient:
      return "discard_transient";
    case FrfMethod::kTransientLpm:
      return "transient_lpm";
  }
  return "?";
}

bool ParseFrfMethod(std::string_view text, FrfMethod* method) {
  for (FrfMethod m : {FrfMethod::kDiscardTransient, FrfMethod::kTransientLpm})
    if (text == ToString(m)) {
      *method = m;
      return true;
    }
  return false;
}

}  // namespace eol::analysis
