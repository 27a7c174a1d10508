// Measurements, limits and outcomes, in OpenHTF's vocabulary.
//
// A measurement is declared (name, unit, limits, marginal band, doc) by the recipe and
// filled by analysis. Test outcomes: PASS, FAIL (the motor is out of limits), ERROR (the
// station failed: it says nothing about the motor), ABORTED (the test was interrupted).
#pragma once

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace eol::analysis {

enum class Outcome { kPass, kFail, kError, kAborted };
inline constexpr std::array kAllOutcomes = {Outcome::kPass, Outcome::kFail, Outcome::kError,
                                            Outcome::kAborted};
const char* ToString(Outcome o);  // "PASS", "FAIL", "ERROR", "ABORTED"
std::optional<Outcome> ParseOutcome(const std::string& s);

// Closed interval [lo, hi]; an absent bound is open. A value inside the limits but within
// `marginal` of a bound is flagged marginal (still a pass).
struct Limit {
  std::optional<double> lo;
  std::optional<double> hi;
  double marginal = 0.0;
};

struct MeasurementSpec {
  std::string name;  // carries its unit: resonance_f_hz, winding_r_ohm, ...
  std::string unit;
  std::string doc;
  Limit limit;
};

// A value with its standard uncertainty (NaN when unknown).
struct Estimate {
  double value;
  double sigma;
};

enum class MeasurementOutcome { kPass, kFail, kUnset };
inline constexpr std::array kAllMeasurementOutcomes = {
    MeasurementOutcome::kPass, MeasurementOutcome::kFail, MeasurementOutcome::kUnset};
const char* ToString(MeasurementOutcome o);  // "PASS", "FAIL", "UNSET"

struct Measurement {
  std::string name;
  std::string unit;
  std::string doc;
  double value = 0.0;
  double sigma = 0.0;
  Limit limit;
  MeasurementOutcome outcome = MeasurementOutcome::kUnset;
  bool marginal = false;
};

struct Verdict {
  Outcome outcome = Outcome::kError;
  std::vector<std::string> reasons;  // empty for a clean PASS
  std::vector<Measurement> measurements;
};

// Judges every declared measurement against its limits. A declared measurement whose value
// is missing or not finite makes the verdict ERROR (never PASS, never FAIL: the station could
// not measure). Otherwise any measurement out of limits makes it FAIL, with one reason each.
Verdict Judge(const std::vector<MeasurementSpec>& specs,
              const std::map<std::string, Estimate>& values);

}  // namespace eol::analysis
