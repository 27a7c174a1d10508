// The fit summary's one field list to and from JSON: what the store keeps in a record's "fit",
// what GET /api/tests/<id> serves and what `eol analyze --json` prints under "fit".
//
// {"model": "R+sL+parallel-RLC", "usable": true, "termination": "converged", "message": "...",
//  "params": {"<name>": {"value": 0.5, "sigma": 1e-4, "unit": "ohm"}, ...},
//  "chi2": 411.2, "dof": 395, "chi2_per_dof": 1.04, "iterations": 7,
//  "sigma_estimated": false, "estimated_sigma": 0.0,
//  "covariance": {"params": ["R_ohm", ...], "matrix": [[...], ...]}}
//
// "params" is keyed by name (readers look parameters up by name); "covariance" names its rows
// in the fit's order, which from_json restores. Not finite numbers are null (json_number.h).
// termination is one of ToString(Termination) (least_squares.h); any other string is refused
// with std::invalid_argument naming the field and the accepted values. Older records have no
// "covariance" or "estimated_sigma": they read back as empty and 0.
#pragma once

#include <nlohmann/json.hpp>

#include "analysis/fit/least_squares.h"
#include "analysis/fit/resonance_fit.h"

namespace eol::analysis {

void to_json(nlohmann::json& j, const Termination& t);
void from_json(const nlohmann::json& j, Termination& t);
void to_json(nlohmann::json& j, const FitSummary& s);
void from_json(const nlohmann::json& j, FitSummary& s);

}  // namespace eol::analysis
