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
#include "drivers/io/motor_json.h"
#include "station/daemon/recipe.h"

namespace eol::station {

// The winding-temperature reference (recipe "conditions.winding_temperature_c", station/
// conditions.h) relearned from the golden units, so a recipe taught for a new motor does not
// keep another motor's R (every unit ERROR "winding temperature 384.6 degC"). The rule: the
// golden units are taken to be at the reference temperature t_ref_c (teach at it, or set
// t_ref_c to their temperature first), so r_ref_ohm becomes their taught centre of
// winding_r_ohm (mean, or median for --method mad; outliers left out); a warning when the old
// reference read them outside kImplausibleWindingLoC..HiC (conditions.h). Only when the recipe has
// a winding reference and a winding_r_ohm limit was taught; kept otherwise (the note says why).
struct WindingReference {
  bool relearned = false;
  double old_r_ref_ohm = 0.0;
  double r_ref_ohm = 0.0;
  double t_ref_c = 20.0;
  // The golden units' temperature read with the old reference (NaN when not relearned).
  double golden_c_with_old = 0.0;
  std::string note;     // one sentence: what was done, for the description and the report
  std::string warning;  // set when the old reference read the golden units as implausible
};
WindingReference RelearnWindingReference(const Recipe& recipe,
                                         const analysis::TeachSummary& summary);

// The excitation design's nominal motor (recipe "excitation_design.nominal": the good motor the
// recipe expects, which must pass the recipe's own limits) relearned from the golden units when
// the taught recipe `taught` (limits and winding reference already taught) disagrees with it
// (NominalDisagreement, station/daemon/recipe.h), so limits taught from real units are not refused
// against a design value they have moved away from (Q 50 of the design against taught limits
// up to 43.5); a design nominal inside the taught limits is kept (the engineer's statement, and
// the excitation was designed at it). Relearned, each of f0, Q, R, L and Rp becomes the golden
// units' taught centre of its measurement (resonance_f_hz, resonance_q, winding_r_ohm,
// winding_l_h, motional_rp_ohm) where one was taught; the others are kept. The excitation is
// not redesigned: a proposal whose excitation no longer reaches its sigma_f0 at the relearned
// nominal is written but not loadable (ExcitationShortOfDesign) until eol design-excitation.
struct NominalRelearned {
  bool relearned = false;  // the recipe has an excitation_design and at least one was taught
  analysis::MotionalImpedance nominal;
  std::string note;  // one sentence: each value old -> new, for the description and report
};
NominalRelearned RelearnNominal(const Recipe& taught, const analysis::TeachSummary& summary);

// "" when the taught recipe `taught` loads; else why not, with the fix. Called on a proposal
// that validates except for its excitation requirement (RecipeParseOptions
// check_excitation_design false): units unlike the design (a lower Q) can leave the excitation
// short of its sigma_f0_hz at the relearned nominal. Teach still writes that proposal, saying
// so, and nothing loads or approves it until `eol design-excitation` has redesigned it.
std::string ExcitationShortOfDesign(const nlohmann::json& taught, const std::string& source);

// Golden units of another motor: the medians of the golden units' resonance_f_hz,
// winding_r_ohm, winding_l_h and motional_residue_ohm_per_s against what the recipe expects:
// the centre of its two-sided limit on each (else its excitation_design nominal motor), and
// for f0 also its analysis f0 window. One sentence per quantity that disagrees: f0 more than
// kForeignF0Share from the recipe's centre or outside the window; the others more than a factor
// kForeignFactor. Empty when they belong to the recipe's motor (or it expects nothing).
inline constexpr double kForeignF0Share = 0.15;
inline constexpr double kForeignFactor = 1.5;
std::vector<std::string> ForeignGoldenUnits(const Recipe& recipe,
                                            const std::vector<analysis::GoldenUnit>& golden);
// The refusal of ForeignGoldenUnits' findings, one text for `eol teach` and POST /api/teach:
// "the golden units are not recipe <id>'s motor: <each finding>; teach a recipe made for their
// motor, or <how_to_force> to teach this one from them (recorded in the taught recipe)".
std::string ForeignGoldenRefusal(const Recipe& recipe, const std::vector<std::string>& foreign,
                                 const std::string& how_to_force);

// The recipe's JSON with the taught limits and masks, the winding reference and the excitation
// design's nominal relearned (RelearnWindingReference, RelearnNominal), version + 1, a note in the
// description. `forced_foreign` holds ForeignGoldenUnits' sentences when teaching from them was
// forced: the description and the approval note record it (the audit of the proposal).
nlohmann::json TaughtRecipeJson(const Recipe& recipe, const analysis::TeachSummary& summary,
                                const analysis::TeachOptions& options,
                                const std::vector<std::string>& forced_foreign = {});

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
    kForeignUnits,   // the golden units are another motor's (ForeignGoldenUnits), not forced
  };
  Kind kind = Kind::kProposed;
  std::string message;  // why, for kBadSerial, kInvalidRecipe and kForeignUnits
  // kProposed and kNotUsable: TeachSummaryJson plus "skipped" (["<serial>: <why>"]) and
  // "previous" ({id, version, hash} of `recipe`); kProposed adds "recipe", "recipe_hash" and
  // "foreign_forced" (the findings taught from under force_foreign, else empty).
  // kForeignUnits: {"foreign": [each finding], "skipped", "previous"}.
  nlohmann::json report;
};

// `store_mu` is held only while reading `store`, not while teaching. Golden units of another
// motor (ForeignGoldenUnits) are refused (kForeignUnits, ForeignGoldenRefusal) unless
// `force_foreign`: then taught, and the proposed recipe records it (TaughtRecipeJson), as
// `eol teach --force-foreign` does.
TeachResult TeachFromStore(db::Store& store, std::mutex& store_mu, const Recipe& recipe,
                           const std::vector<std::string>& serials,
                           const analysis::TeachOptions& options, bool force_foreign = false);

// Detectability options for the recipe's excitation and fit on a motor's model: `motor`'s
// winding (R, L), torque transmission and rotor chain with its fixture when given (a motor JSON,
// drivers/io/motor_json.h), else the built-in chain (analysis/model/rotor_chain.h: the ten-pole
// motor, 390 Hz in its fixture) with DetectabilityOptions' winding. `k_fixture_nm_per_rad` > 0
// replaces the fixture spring (and stands one in for a motor JSON's rigid fixture); the
// good-unit spread is the recipe's two-sided limits taken as +-limit_sigmas (override
// unit_spread afterwards for a measured spread).
analysis::DetectabilityOptions DetectabilityOptionsFor(const Recipe& recipe,
                                                       const io::MotorSpec* motor,
                                                       double k_fixture_nm_per_rad,
                                                       double limit_sigmas, double required_sigmas);

// The model is another motor than the recipe's when its good rotor's mode (PredictChain) lies
// more than this share away from the f0 the recipe expects.
inline constexpr double kDetectabilityF0Tolerance = 0.15;

// Why the motor model (`motor`, or the built-in chain when null) cannot stand for the recipe's
// motor, or "" when it can (or when the recipe states no f0: no excitation_design nominal and
// no two-sided resonance_f_hz limit). The model's good rotor is taken in the model's own
// fixture (a what-if fixture stiffness changes f0 on purpose, not the motor); the f0 the
// recipe expects is its excitation_design nominal's, else the middle of its resonance_f_hz
// limits. A prediction made on the ten-pole chain for a recipe of another motor is silently
// wrong, so `eol detectability` and GET /api/detectability refuse it with this text.
std::string DetectabilityModelMismatch(const Recipe& recipe, const io::MotorSpec* motor);

nlohmann::json DetectabilityJson(const analysis::DetectabilitySummary& summary,
                                 const std::string& k_fixture_source,
                                 const std::string& spread_source, double required_sigmas);

}  // namespace eol::station
