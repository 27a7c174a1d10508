// The field lists of measurements and verdicts to and from JSON, used by the store (a
// record's "measurements"), the API, the status board and the CLI.
//
// Limit:       {"lo": 370 | null, "hi": 420 | null, "marginal": 3}      (null: open side)
// Measurement: {"name", "unit", "doc", "value", "sigma", "limit": Limit,
//               "outcome": "PASS" | "FAIL" | "UNSET", "marginal": bool}  (value, sigma: null
//               when not finite, json_number.h)
// Verdict:     {"outcome": "PASS" | "FAIL" | "ERROR" | "ABORTED", "reasons": [...],
//               "measurements": [Measurement, ...]}
//
// An outcome string outside those lists is refused with std::invalid_argument naming the
// field and the accepted values (enum_names.h); the strings are those of records stored since
// schema v1, so old databases read back unchanged.
#pragma once

#include <nlohmann/json.hpp>

#include "analysis/qc/measurement.h"

namespace eol::analysis {

void to_json(nlohmann::json& j, const Outcome& o);
void from_json(const nlohmann::json& j, Outcome& o);
void to_json(nlohmann::json& j, const MeasurementOutcome& o);
void from_json(const nlohmann::json& j, MeasurementOutcome& o);
void to_json(nlohmann::json& j, const Limit& l);
void from_json(const nlohmann::json& j, Limit& l);
void to_json(nlohmann::json& j, const Measurement& m);
void from_json(const nlohmann::json& j, Measurement& m);
// {"code": "limit", "text": "..."} or {"code": "interlock", "text": "...", "cause":
// "interlock.door_open"} ("cause" only when set; a record without it reads with none); a plain
// string (records written before reasons had codes) reads as code kLegacy; an unknown code is
// refused naming it.
void to_json(nlohmann::json& j, const Reason& r);
void from_json(const nlohmann::json& j, Reason& r);
void to_json(nlohmann::json& j, const Verdict& v);
void from_json(const nlohmann::json& j, Verdict& v);

}  // namespace eol::analysis
