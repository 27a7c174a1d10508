// A recipe: everything that is specific to one motor type, one JSON file in recipes/.
//
// {
//   "id": "pmsm-10pole", "version": 1, "description": "...",
//   "motor":      {"poles": 10, "rotor_inertia_kg_m2": 1.0e-4},
//   "excitation": {"f_lo_hz": 200, "f_hi_hz": 800, "line_spacing_hz": 1, "sample_rate_hz": 8000,
//                  "peak_v": 2.0, "periods": 4, "transient_periods": 1, "phase_pair": 0 |
//                  "phase_pairs": [0, 1, 2], "crest_for": "voltage" (default) | "current"},
//                  crest_for "current": the phases minimise the crest factor of the current
//                  through the excitation_design block's nominal motor (required then), for a
//                  motor whose current range limits the amplitude (analysis/signal/multisine.h)
//   "fixture":    {"clamp_pressure_bar": {"lo": 4.5, "hi": 6.5}, "clamp_timeout_s": 2.0,
//                  "release_timeout_s": 2.0},
//   "analysis":   {"f0_min_hz": 250, "f0_max_hz": 700, "q_min": 5, "q_max": 500,
//                  "frf_method": "discard_transient" (default: drop transient_periods, average
//                  the rest) | "transient_lpm" (keep every period, remove the start transient;
//                  analysis/signal/transient_frf.h)},
//   "retest":     {"max_tests_per_serial": 3},                                    optional
//   "limits": [ {"name": "resonance_f_hz", "unit": "Hz", "lo": 370, "hi": 420,
//                "marginal": 3, "doc": "..."}, ... ],
//                "unit" is optional: the measurement owns it (analysis/qc/measurement_names.h
//                UnitOf); a limit stating another ("kHz" on resonance_f_hz) is refused naming
//                both. Limits on resonance_f_hz and resonance_f_ref_pressure_hz lie inside the
//                analysis f0 window (itself inside the excited band).
//   "masks": [ {"name": "re_z_low_band", "quantity": "re_ohm" | "abs_ohm",
//               "max_lines_outside": 0, "guard_sigma": 3,
//               "points": [{"f_hz": 300, "hi": 0.75}, {"f_hz": 365, "hi": 0.75}]} ]  optional
//   "conditions": {"winding_temperature_c": {"r_ref_ohm": 0.5, "t_ref_c": 20, "lo": 0, "hi": 45},
//                  "excitation_v_rms": {"lo": 1.2, "hi": 1.45}, "excitation_a_rms": {...},
//                  "out_of_window": "error" | "record"}       optional, station/daemon/conditions.h
//   "instructions": {"fail": "...", "error": "...", "aborted": "..."}  optional, each optional
//   "bond_index": {"f0_exponent": 5.3, "f0_ref_hz": 390, "residue_ref_ohm_per_s": 25.6,
//                  "f0": "resonance_f_hz" (default) | "resonance_f_ref_pressure_hz",
//                  "residue_to_f0": 12}
//                  optional; required by a limit on bond_index_pct (analysis/qc/bond_index.h;
//                  eol teach writes it from the golden units). residue_to_f0 is the motor's
//                  defect direction, d ln(residue) / -d ln(f0) of softer bonds, in (0, 1000]
//                  (default 12, the ten-pole motor's): eol teach weighs the index for it
//   "f0_pressure": {"exponent": 0.114, "pressure_ref_bar": 5.5}
//                  optional; required by a limit on resonance_f_ref_pressure_hz
//                  (analysis/qc/f0_pressure.h; eol teach writes it when the golden units' f0
//                  follows their clamp pressure significantly)
//   "sequential": {"extend_periods": 8, "max_extensions": 1, "confidence_z": 3}   optional
//                  (SequentialPolicy below)
//   "excitation_design": {"sigma_f0_hz": 0.009, "verdict_margin_hz": 0, "margin_z": 3,
//                  "noise_v_rms": 0.002, "noise_a_rms": 0.001, "max_peak_v": 10,
//                  "current_full_scale_a": 2, "max_v_rms": 8, "max_a_rms": 3,
//                  "lines_per_half_power_band": 2, "min_periods": 2,
//                  "nominal": {"r_ohm": 0.5, "l_h": 0.002, "rp_ohm": 0.53, "f0_hz": 390, "q": 50}}
//                  optional (analysis/signal/excitation_design.h): the std(f0) the excitation
//                  must reach at the nominal motor (the Cramer-Rao bound with the DAQ's noise);
//                  a recipe whose excitation does not is refused, saying how to choose it for
//                  a motor (a stated fraction of the good units' std(f0), e.g. 1/10). The
//                  nominal is the good motor the recipe expects: it must pass the recipe's own
//                  limits (f0, Q, R, L, Rp, residue, bond index) and read inside the winding-
//                  temperature window, or the recipe is refused naming what disagrees. The
//                  amplitude limits are max_peak_v, max_v_rms and max_a_rms (heating; optional) and
//                  0.8 of the current channel's full scale (optional). `eol design-excitation`
//                  writes the shortest excitation that meets it.
// }
// Validated on load: every message names the JSON path and the rule broken, and a recipe
// that fails validation is never used. The hash is the SHA-256 of the canonical JSON (keys
// sorted, no whitespace), so formatting changes do not change it.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/bond_index.h"
#include "analysis/qc/curve_mask.h"
#include "analysis/qc/f0_pressure.h"
#include "analysis/qc/measurement.h"
#include "analysis/signal/excitation_design.h"
#include "analysis/signal/multisine.h"
#include "drivers/fixture/fixture.h"
#include "station/daemon/conditions.h"

namespace eol::station {

// Bounds every recipe must respect, physical and of resources: ParseRecipe refuses a recipe
// outside them, naming the field, so a recipe can neither exhaust the station's memory or
// time nor switch off a safety interlock by a window that passes everything.
inline constexpr double kMaxSampleRateHz = 1.0e6;      // the fastest supported DAQ
inline constexpr double kMinLineSpacingHz = 0.05;      // a period of at most 20 s
inline constexpr double kMaxPeriodSamples = 1 << 21;   // samples per period (16 MiB a channel)
inline constexpr int kMaxCrestIterations = 2000;       // crest-factor optimisation (~0.3 s)
inline constexpr double kMaxExcitationS = 60.0;        // excitation per phase pair
inline constexpr double kMinClampPressureBar = 0.5;    // below it the clamp does not hold
inline constexpr double kMaxClampPressureBar = 300.0;  // hydraulic clamps included
inline constexpr double kMaxClampPressureRatio = 2.0;  // hi / lo of the interlock window
inline constexpr std::size_t kMaxMasks = 64;
inline constexpr std::size_t kMaxMaskPoints = 512;
inline constexpr std::size_t kMaxInstructionBytes = 200;

// What the operator does with the unit after a verdict other than PASS: the operator page
// shows it above the technical reason. Each is 1 to kMaxInstructionBytes bytes of UTF-8 text
// without control characters; a key the recipe leaves out keeps its default.
struct OperatorInstructions {
  std::string fail = "Put the rotor in the red reject bin";
  std::string error = "Test the rotor again; if ERROR repeats, call maintenance";
  std::string aborted = "Test the rotor again";
  bool operator==(const OperatorInstructions&) const = default;
};

// Who stands behind the limits (issue 12). A recipe `eol teach` writes is a proposal; the
// station refuses to test with it (at start and on PUT /api/recipe) until an engineer
// approves it: POST /api/recipe/approve (engineer token) or `eol recipe-approve` (both
// audited). A recipe without "approval" was written by hand and counts as approved.
//   "approval": {"state": "proposed" | "approved", "by": text, "at": ISO 8601, "note": text}
// "by" and "at" are required; each text is 1 to kMaxInstructionBytes bytes.
struct RecipeApproval {
  std::string state;  // "proposed" or "approved"
  std::string by;     // the teaching tool, or the approving engineer (token or --by name)
  std::string at;
  std::string note;  // optional
  bool operator==(const RecipeApproval&) const = default;
};

// Sequential decision (issue 16): after each phase pair's first look (the excitation's periods),
// while a measurement is undecided at confidence_z (analysis/qc/measurement.h
// UndecidedMeasurements: within z sigma, or its marginal band, of a bound) the pair is excited
// again for extend_periods periods from rest, and the looks are combined line by line by
// inverse variance (analysis/frf.h CombineIndependent) and analysed again; at most
// max_extensions times. Units far from every limit stop after the first look.
//   "sequential": {"extend_periods": 8, "max_extensions": 1, "confidence_z": 3}
struct SequentialPolicy {
  std::size_t extend_periods = 8;
  int max_extensions = 1;
  double confidence_z = 3.0;
  bool operator==(const SequentialPolicy&) const = default;
};

struct Recipe {
  std::string id;
  int version = 0;
  std::string description;
  std::string hash;  // SHA-256 hex of the canonical JSON

  int poles = 10;
  double rotor_inertia_kg_m2 = 0.0;  // the given J_r of the paper's eq. 24-30

  // excitation.crest_load_ohm is the excitation_design's nominal motor when "crest_for" is
  // "current" (set by ParseRecipe), empty otherwise.
  analysis::MultisineOptions excitation;
  bool crest_for_current = false;
  std::size_t periods = 4;                                  // averaged
  std::size_t transient_periods = 1;                        // played first and dropped
  drivers::PhasePair phase_pair = drivers::PhasePair::kUV;  // the first of phase_pairs
  // Measured in this order in one clamping ("phase_pairs": [0, 1, 2], or "phase_pair": 0 for
  // one). The first pair's measurements and curves carry the plain names (limits, masks,
  // statistics and teaching use them); each further pair's get "@V-W" / "@W-U" appended
  // and are judged against the same limits; the verdict is the worst of the pairs.
  std::vector<drivers::PhasePair> phase_pairs = {drivers::PhasePair::kUV};

  double clamp_pressure_lo_bar = 4.5;
  double clamp_pressure_hi_bar = 6.5;
  double clamp_timeout_s = 2.0;
  double release_timeout_s = 2.0;

  // Retest policy: how many tests one serial may have in all (first test and retests); a
  // serial beyond it is refused before clamping ("send to rework"). 0 = no limit.
  int max_tests_per_serial = 3;

  analysis::ImpedanceAnalysisOptions analysis;
  std::vector<analysis::MeasurementSpec> limits;
  std::vector<analysis::CurveMask> masks;
  ConditionWindows conditions;
  OperatorInstructions instructions;
  std::optional<RecipeApproval> approval;
  std::optional<analysis::BondIndexDefinition> bond_index;
  std::optional<analysis::F0PressureDefinition> f0_pressure;
  // The precision the excitation is designed for (issue 16); the recipe's own excitation must
  // reach it at the nominal motor, or the recipe is refused.
  std::optional<analysis::ExcitationRequirement> excitation_design;
  std::optional<SequentialPolicy> sequential;

  // Periods the estimator uses of one look: every period played for "transient_lpm" (it
  // removes the start transient), the averaged ones after the dropped transient otherwise.
  std::size_t AnalysedPeriods() const;

  bool Approved() const { return !approval || approval->state == "approved"; }
  // Empty when Approved(); else why the station refuses it, naming how to approve it.
  std::string WhyNotApproved() const;

  // Every declared measurement: the scalar limits, then one per mask.
  std::vector<analysis::MeasurementSpec> Specs() const;

  nlohmann::json source;  // the recipe as loaded
};

// Why the nominal motor `n` (the excitation design's "good motor the recipe expects") and the
// recipe's limits describe different motors, or "" when they agree: `n` must pass the limits
// it determines (f0, Q, R, L, Rp, residue, bond index) and read inside the winding-temperature
// window. ParseRecipe refuses a recipe whose own nominal disagrees; eol teach relearns the
// nominal when the taught limits disagree with it (station/daemon/qc_service.h RelearnNominal).
std::string NominalDisagreement(const Recipe& recipe, const analysis::MotionalImpedance& n);

struct RecipeParseOptions {
  // false only for `eol design-excitation`, which reads a recipe whose excitation does not yet
  // meet its stated requirement in order to design one that does.
  bool check_excitation_design = true;
};
// Throws io::ConfigError with "<source>: <json path>: <rule>".
Recipe ParseRecipe(const nlohmann::json& j, const std::string& source,
                   const RecipeParseOptions& options = {});
Recipe LoadRecipe(const std::string& path);
// Writes a recipe's JSON (2-space indent) to `path` through `path`.tmp and a rename, so a
// reader never sees half a file (atomic on one file system). Throws std::runtime_error naming
// the file when it cannot be written.
void WriteRecipeFile(const std::string& path, const nlohmann::json& j);

// The recipe as JSON in the schema ParseRecipe reads (every key, defaults written out), so
// that ParseRecipe(RecipeToJson(r)) gives r back (tests/station/recipe_test.cc). Used for
// every recipe the station writes (a taught proposal); the hash stays that of the file's own
// JSON as loaded.
nlohmann::json RecipeToJson(const Recipe& r);
// One curve mask in the recipe's "masks" schema.
nlohmann::json MaskJson(const analysis::CurveMask& mask);
// The recipe's "excitation_design" schema, every key written out.
nlohmann::json ExcitationDesignJson(const analysis::ExcitationRequirement& d);
// The recipe's "instructions" schema, every key written out (the page reads it from
// GET /api/recipe).
nlohmann::json InstructionsJson(const OperatorInstructions& instructions);
// One limit in the recipe's "limits" schema ({"name", "unit", "doc", "lo"?, "hi"?, "marginal"};
// an open side is left out). Also how a taught or benched limit is reported.
nlohmann::json LimitJson(const analysis::MeasurementSpec& spec);
// The recipe's "bond_index" and "f0_pressure" blocks (also how teach reports them).
nlohmann::json BondIndexJson(const analysis::BondIndexDefinition& d);
nlohmann::json F0PressureJson(const analysis::F0PressureDefinition& d);

std::string Sha256Hex(const std::string& data);
std::string CanonicalHash(const nlohmann::json& j);

}  // namespace eol::station
