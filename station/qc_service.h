// Learning limits and predicting detectability, shared by the CLI (`eol teach`,
// `eol detectability`) and the HTTP API (POST /api/teach, GET /api/detectability), so both
// give the same recipe and the same report.
#pragma once

#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/qc/detectability.h"
#include "analysis/qc/teach.h"
#include "db/store.h"
#include "db/test_record.h"
#include "station/recipe.h"

namespace eol::station {

// The recipe's JSON with the taught limits and masks, version + 1, a note in the description.
nlohmann::json TaughtRecipeJson(const Recipe& recipe, const analysis::TeachSummary& summary,
                                const analysis::TeachOptions& options);

// The summary as JSON: usable, bounds, k, units given/used/needed, rejected, limits, masks.
nlohmann::json TeachSummaryJson(const analysis::TeachSummary& summary,
                                const analysis::TeachOptions& options);

// A stored test as a golden unit: its measurements and its "impedance" curve.
analysis::GoldenUnit GoldenFromRecord(const db::TestRecord& record, const std::string& label);

// Teaching from stored units (POST /api/teach): the latest stored test of each serial teaches
// unless there is none or it is ERROR or ABORTED (those are skipped, with the reason). The
// result is a proposal only: nothing changes until the proposed recipe is put in use.
struct TeachResult {
  enum class Kind {
    kProposed,       // report holds the proposed recipe (version + 1) and its hash
    kBadSerial,      // a serial is malformed (message names it); nothing was read
    kNotUsable,      // the summary says the units cannot teach; report says why
    kInvalidRecipe,  // the taught recipe fails validation (message names the field)
  };
  Kind kind = Kind::kProposed;
  std::string message;  // why, for kBadSerial and kInvalidRecipe
  // kProposed and kNotUsable: TeachSummaryJson plus "skipped" (["<serial>: <why>"]) and
  // "previous" ({id, version, hash} of `recipe`); kProposed adds "recipe" and "recipe_hash".
  nlohmann::json report;
};

// `store_mu` is held only while reading `store`, not while teaching.
TeachResult TeachFromStore(db::Store& store, std::mutex& store_mu, const Recipe& recipe,
                           const std::vector<std::string>& serials,
                           const analysis::TeachOptions& options);

// Detectability options for the recipe's excitation and fit; `k_fixture_nm_per_rad` > 0
// replaces the chain's fixture spring; the good-unit spread is the recipe's two-sided limits
// taken as +-limit_sigmas (override unit_spread afterwards for a measured spread).
analysis::DetectabilityOptions DetectabilityOptionsFor(const Recipe& recipe,
                                                       double k_fixture_nm_per_rad,
                                                       double limit_sigmas, double required_sigmas);

nlohmann::json DetectabilityJson(const analysis::DetectabilitySummary& summary,
                                 const std::string& k_fixture_source,
                                 const std::string& spread_source, double required_sigmas);

}  // namespace eol::station
