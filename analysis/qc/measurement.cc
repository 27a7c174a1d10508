#include "analysis/qc/measurement.h"

#include <cmath>
#include <sstream>

namespace eol::analysis {

const char* ToString(Outcome o) {
  switch (o) {
    case Outcome::kPass:
      return "PASS";
    case Outcome::kFail:
      return "FAIL";
    case Outcome::kError:
      return "ERROR";
    case Outcome::kAborted:
      return "ABORTED";
  }
  return "ERROR";
}

std::optional<Outcome> ParseOutcome(const std::string& s) {
  for (Outcome o : {Outcome::kPass, Outcome::kFail, Outcome::kError, Outcome::kAborted})
    if (s == ToString(o)) return o;
  return std::nullopt;
}

const char* ToString(MeasurementOutcome o) {
  switch (o) {
    case MeasurementOutcome::kPass:
      return "PASS";
    case MeasurementOutcome::kFail:
      return "FAIL";
    case MeasurementOutcome::kUnset:
      return "UNSET";
  }
  return "UNSET";
}

Verdict Judge(const std::vector<MeasurementSpec>& specs,
              const std::map<std::string, Estimate>& values) {
  Verdict v;
  bool missing = false, failed = false;
  for (const MeasurementSpec& spec : specs) {
    Measurement m;
    m.name = spec.name;
    m.unit = spec.unit;
    m.doc = spec.doc;
    m.limit = spec.limit;
    auto it = values.find(spec.name);
    std::ostringstream reason;
    if (it == values.end() || !std::isfinite(it->second.value)) {
      m.value = std::nan("");
      m.sigma = std::nan("");
      m.outcome = MeasurementOutcome::kUnset;
      missing = true;
      reason << spec.name << ": not measured";
      v.reasons.push_back(reason.str());
      v.measurements.push_back(m);
      continue;
    }
    m.value = it->second.value;
    m.sigma = it->second.sigma;
    const Limit& l = spec.limit;
    if (l.lo && m.value < *l.lo) {
      reason << spec.name << " = " << m.value << " " << spec.unit << " below lower limit " << *l.lo;
    } else if (l.hi && m.value > *l.hi) {
      reason << spec.name << " = " << m.value << " " << spec.unit << " above upper limit " << *l.hi;
    }
    if (!reason.str().empty()) {
      m.outcome = MeasurementOutcome::kFail;
      failed = true;
      v.reasons.push_back(reason.str());
    } else {
      m.outcome = MeasurementOutcome::kPass;
      m.marginal = (l.lo && m.value < *l.lo + l.marginal) || (l.hi && m.value > *l.hi - l.marginal);
    }
    v.measurements.push_back(m);
  }
  v.outcome = missing ? Outcome::kError : failed ? Outcome::kFail : Outcome::kPass;
  return v;
}

}  // namespace eol::analysis
