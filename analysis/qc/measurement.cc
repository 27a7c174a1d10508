#include "analysis/qc/measurement.h"

#include <algorithm>
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

Outcome Worse(Outcome a, Outcome b) {
  auto severity = [](Outcome o) {
    switch (o) {
      case Outcome::kPass:
        return 0;
      case Outcome::kFail:
        return 1;
      case Outcome::kError:
        return 2;
      case Outcome::kAborted:
        return 3;
    }
    return 2;
  };
  return severity(a) >= severity(b) ? a : b;
}

const char* ToString(ReasonCode c) {
  switch (c) {
    case ReasonCode::kLimit:
      return "limit";
    case ReasonCode::kMask:
      return "mask";
    case ReasonCode::kCondition:
      return "condition";
    case ReasonCode::kInterlock:
      return "interlock";
    case ReasonCode::kFixture:
      return "fixture";
    case ReasonCode::kAcquisition:
      return "acquisition";
    case ReasonCode::kAnalysis:
      return "analysis";
    case ReasonCode::kAborted:
      return "aborted";
    case ReasonCode::kStore:
      return "store";
    case ReasonCode::kLockout:
      return "lockout";
    case ReasonCode::kRetestLimit:
      return "retest_limit";
    case ReasonCode::kSelfCheck:
      return "self_check";
    case ReasonCode::kInternal:
      return "internal";
    case ReasonCode::kLegacy:
      return "legacy";
    case ReasonCode::kClipped:
      return "clipped";
  }
  return "internal";
}

std::optional<ReasonCode> ParseReasonCode(const std::string& s) {
  for (int i = 0; i <= static_cast<int>(ReasonCode::kClipped); ++i)
    if (s == ToString(static_cast<ReasonCode>(i))) return static_cast<ReasonCode>(i);
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
              const std::map<std::string, Estimate>& values, ReasonCode out_of_limits) {
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
      v.reasons.push_back({ReasonCode::kAnalysis, reason.str()});
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
      v.reasons.push_back({out_of_limits, reason.str()});
    } else {
      m.outcome = MeasurementOutcome::kPass;
      m.marginal = (l.lo && m.value < *l.lo + l.marginal) || (l.hi && m.value > *l.hi - l.marginal);
    }
    v.measurements.push_back(m);
  }
  v.outcome = missing ? Outcome::kError : failed ? Outcome::kFail : Outcome::kPass;
  return v;
}

std::vector<std::string> UndecidedMeasurements(const std::vector<Measurement>& measurements,
                                               double z) {
  std::vector<std::string> out;
  for (const Measurement& m : measurements) {
    if (!std::isfinite(m.value)) continue;
    double band = m.limit.marginal;
    if (std::isfinite(m.sigma) && m.sigma > 0.0) band = std::max(band, z * m.sigma);
    if (!(band > 0.0)) continue;
    const bool near_lo = m.limit.lo && std::abs(m.value - *m.limit.lo) < band;
    const bool near_hi = m.limit.hi && std::abs(m.value - *m.limit.hi) < band;
    if (near_lo || near_hi) out.push_back(m.name);
  }
  return out;
}

}  // namespace eol::analysis
