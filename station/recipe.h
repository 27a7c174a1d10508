// A recipe: everything that is specific to one motor type, one JSON file in recipes/.
//
// {
//   "id": "pmsm-10pole", "version": 1, "description": "...",
//   "motor":      {"poles": 10, "rotor_inertia_kg_m2": 1.0e-4},
//   "excitation": {"f_lo_hz": 200, "f_hi_hz": 800, "line_spacing_hz": 1, "sample_rate_hz": 8000,
//                  "peak_v": 2.0, "periods": 4, "transient_periods": 1, "phase_pair": 0 |
//                  "phase_pairs": [0, 1, 2]},
//   "fixture":    {"clamp_pressure_bar": {"lo": 4.5, "hi": 6.5}, "clamp_timeout_s": 2.0,
//                  "release_timeout_s": 2.0},
//   "analysis":   {"f0_min_hz": 250, "f0_max_hz": 700, "q_min": 5, "q_max": 500},
//   "retest":     {"max_tests_per_serial": 3},                                    optional
//   "limits": [ {"name": "resonance_f_hz", "unit": "Hz", "lo": 370, "hi": 420,
//                "marginal": 3, "doc": "..."}, ... ],
//   "masks": [ {"name": "re_z_low_band", "quantity": "re_ohm" | "abs_ohm",
//               "max_lines_outside": 0, "guard_sigma": 3,
//               "points": [{"f_hz": 300, "hi": 0.75}, {"f_hz": 365, "hi": 0.75}]} ]  optional
//   "conditions": {"winding_temperature_c": {"r_ref_ohm": 0.5, "t_ref_c": 20, "lo": 0, "hi": 45},
//                  "excitation_v_rms": {"lo": 1.2, "hi": 1.45}, "excitation_a_rms": {...},
//                  "out_of_window": "error" | "record"}       optional, station/conditions.h
// }
// Validated on load: every message names the JSON path and the rule broken, and a recipe
// that fails validation is never used. The hash is the SHA-256 of the canonical JSON (keys
// sorted, no whitespace), so formatting changes do not change it.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/curve_mask.h"
#include "analysis/qc/measurement.h"
#include "analysis/signal/multisine.h"
#include "drivers/fixture/fixture.h"
#include "station/conditions.h"

namespace eol::station {

struct Recipe {
  std::string id;
  int version = 0;
  std::string description;
  std::string hash;  // SHA-256 hex of the canonical JSON

  int poles = 10;
  double rotor_inertia_kg_m2 = 0.0;  // the given J_r of the paper's eq. 24-30

  analysis::MultisineOptions excitation;
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

  // Every declared measurement: the scalar limits, then one per mask.
  std::vector<analysis::MeasurementSpec> Specs() const;

  nlohmann::json source;  // the recipe as loaded
};

// Throws io::ConfigError with "<source>: <json path>: <rule>".
Recipe ParseRecipe(const nlohmann::json& j, const std::string& source);
Recipe LoadRecipe(const std::string& path);

// The recipe as JSON in the schema ParseRecipe reads (every key, defaults written out), so
// that ParseRecipe(RecipeToJson(r)) gives r back (tests/station/recipe_test.cc). Used for
// every recipe the station writes (a taught proposal); the hash stays that of the file's own
// JSON as loaded.
nlohmann::json RecipeToJson(const Recipe& r);
// One curve mask in the recipe's "masks" schema.
nlohmann::json MaskJson(const analysis::CurveMask& mask);

std::string Sha256Hex(const std::string& data);
std::string CanonicalHash(const nlohmann::json& j);

}  // namespace eol::station
