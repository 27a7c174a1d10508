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
#include <utility>
#include <vector>

namespace eol::analysis {

enum class Outcome { kPass, kFail, kError, kAborted };
inline constexpr std::array kAllOutcomes = {Outcome::kPass, Outcome::kFail, Outcome::kError,
                                            Outcome::kAborted};
const char* ToString(Outcome o);  // "PASS", "FAIL", "ERROR", "ABORTED"
std::optional<Outcome> ParseOutcome(const std::string& s);

// The more severe of two outcomes, in the order ABORTED > ERROR > FAIL > PASS. Why this order:
// a FAIL says something about the motor, an ERROR says the station could not measure it, so
// a unit with one phase pair FAILed and another in ERROR has not been fully measured and must
// be re-tested, not scrapped on partial evidence (ERROR over FAIL). ABORTED (someone or
// something stopped the test) tops ERROR: the test never ran to its end, whatever its
// completed parts showed. Symmetric; PASS only when both are PASS.
Outcome Worse(Outcome a, Outcome b);

// Why a verdict is what it is: a stable machine-readable code (what databases, dashboards
// and tests match on) with the human sentence (what the operator reads). The codes are
// stored by name (ToString); never rename one, only add.
enum class ReasonCode {
  kLimit,        // "limit": a measurement outside its recipe limits (FAIL)
  kMask,         // "mask": the impedance curve outside a recipe mask (FAIL)
  kCondition,    // "condition": a test condition outside its recipe window (ERROR)
  kInterlock,    // "interlock": door, emergency stop, part, clamp or heartbeat (ERROR)
  kFixture,      // "fixture": the fixture controller failed or did not answer (ERROR)
  kAcquisition,  // "acquisition": the DAQ could not record (ERROR)
  kAnalysis,     // "analysis": the recording or FRF could not be analysed, or a declared
                 //   measurement has no value (ERROR)
  kAborted,      // "aborted": the test was stopped (ABORTED)
  kStore,        // "store": the database could not store or begin the record (ERROR)
  kLockout,      // "lockout": the station refuses tests until a self-check passes
  kRetestLimit,  // "retest_limit": the serial has used up the recipe's tests
  kSelfCheck,    // "self_check": the verdict of a master part's check of the station
  kInternal,     // "internal": a programming error caught at the sequencer's edge
  kLegacy,       // "legacy": read from a record stored before reasons had codes; the text
                 //   is the stored string (no code is guessed from old text)
  kClipped,      // "clipped": the recording's voltage or current reached the converter's range
                 //   (analysis/signal/clipping.h); nothing was fitted (ERROR)
};
inline constexpr std::array kAllReasonCodes = {
    ReasonCode::kLimit,     ReasonCode::kMask,        ReasonCode::kCondition,
    ReasonCode::kInterlock, ReasonCode::kFixture,     ReasonCode::kAcquisition,
    ReasonCode::kAnalysis,  ReasonCode::kAborted,     ReasonCode::kStore,
    ReasonCode::kLockout,   ReasonCode::kRetestLimit, ReasonCode::kSelfCheck,
    ReasonCode::kInternal,  ReasonCode::kLegacy,      ReasonCode::kClipped};
const char* ToString(ReasonCode c);
std::optional<ReasonCode> ParseReasonCode(const std::string& s);

// `cause`: a finer stable key under the code where one code covers several causes an operator
// acts on differently ("interlock.door_open", "fixture.clamp_not_released"; the station's keys
// are station/daemon/reason_cause.h). Empty when the code says it all, and on every record stored
// before causes existed (never guessed from the text). The operator page's catalogue
// (station/web/i18n/) has the operator's words for every code and every cause.
struct Reason {
  Reason() = default;
  Reason(ReasonCode c, std::string t, std::string k = {})
      : code(c), text(std::move(t)), cause(std::move(k)) {}
  ReasonCode code = ReasonCode::kInternal;
  std::string text;
  std::string cause;
  bool operator==(const Reason&) const = default;
};

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
  std::vector<Reason> reasons;  // empty for a clean PASS
  std::vector<Measurement> measurements;
};

// Judges every declared measurement against its limits. A declared measurement whose value
// is missing or not finite makes the verdict ERROR (never PASS, never FAIL: the station could
// not measure; reason code kAnalysis). Otherwise any measurement out of limits makes it
// FAIL, with one reason each coded `out_of_limits` (kLimit for scalar limits, kMask when the
// specs are mask counts). The station's whole verdict (masks, conditions, phase pairs) is
// station/daemon/judge.h, which calls this.
Verdict Judge(const std::vector<MeasurementSpec>& specs,
              const std::map<std::string, Estimate>& values,
              ReasonCode out_of_limits = ReasonCode::kLimit);

// Sequential decision (issue 16): the measurements whose outcome the data do not yet decide at
// confidence z. A measurement is undecided when it lies closer to a bound it declares, on
// either side, than max(z sigma, marginal): its own uncertainty (where it has one) or the
// recipe's marginal band (statistics without a sigma, e.g. chi2 and mask counts with a band)
// could put it on the other side. A value that is not finite is never undecided (it is
// ERROR, and more data of a broken measurement does not help). Returns their names in order.
std::vector<std::string> UndecidedMeasurements(const std::vector<Measurement>& measurements,
                                               double z);

}  // namespace eol::analysis
