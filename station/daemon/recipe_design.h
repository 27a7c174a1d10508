// A recipe designed from a motor's design data (`eol recipe-new`), and the designed
// excitation written into a recipe (shared with `eol design-excitation`).
//
// ProposeRecipe derives, from the motor's chain (analysis/model/chain_prediction.h) or from
// that chain calibrated to measured good units (CalibrateToGolden):
//   - the excited band one octave either side of the good rotor's mode f0 ([f0/2, 2 f0],
//     rounded out to 10 Hz; its lower edge at most 0.8 of the window's), and the analysis f0
//     window [0.625 f0, 1.75 f0] inside it (its lower edge at most 0.9 of the all-soft mode);
//     the band must stay below 0.45 of the sample rate;
//   - the excitation designed for time (analysis/signal/excitation_design.h, the code behind
//     `eol design-excitation`) from the requirement std(f0) = shift_fraction x (f0 - f0 of a
//     rotor with half its magnets poorly bonded): the smallest defect class the resonance
//     itself is to find; by default a thousandth of it, so that the production spread, not
//     the test's noise, limits detection, and the residue and Q (whose relative noise is about
//     Q times std(f0)/f0) stay far below their good units' spread. On the ten-pole chain:
//     0.014 Hz, met by 2 periods (0.516 s) at 8 V, which reach 0.0062 Hz (the shipped fast
//     recipe: 0.0085 Hz in 0.474 s, set to keep the 5 s recipe's). The record is the
//     shortest that meets it; the amplitude stays at what the amplifier and the
//     current range allow (DesignExcitationForTime would lower it where the shortest record
//     has room to spare; the residue and the second-mode test gain from it), and the recipe's
//     sigma_f0_hz states what that excitation reaches;
//   - the conditions' references: winding R of the motor file at t_ref_c (or the golden units'
//     median), the excitation rms windows 0.8-1.25 (voltage) and 0.5-2 (current) of what the
//     designed excitation drives through the nominal motor;
//   - design limits around the nominal motor, proposals until `eol teach` replaces them:
//     f0 -5 % / +8 %, Q / 3.5 to x 3, R and L +-20 %, residue 0.6-1.55 x, bond index at most
//     55 %, second-mode chi2 drop at most 60, chi2/dof at most 3; no masks (taught only);
//   - the station's clamp-pressure window 4.5-6.5 bar (a property of the fixture, not of the
//     motor file: change it in the proposal when the fixture differs);
//   - the bond index's direction residue_to_f0 from the chain (never a compiled constant),
//     its exponent 0 (the residue alone) until teach sets it from the golden units.
// The recipe is a proposal ("approval": proposed, by "eol recipe-new"), validated by
// ParseRecipe (excitation requirement included) before it is returned.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "analysis/model/chain_prediction.h"
#include "analysis/qc/teach.h"
#include "analysis/signal/excitation_design.h"
#include "drivers/io/motor_json.h"
#include "station/daemon/recipe.h"

namespace eol::station {

struct RecipeNewOptions {
  double sample_rate_hz = 8000.0;  // the station's DAQ
  double noise_v_rms = 0.002;      // the DAQ's channel noise per sample
  double noise_a_rms = 0.001;
  double max_peak_v = 8.0;            // the amplifier
  double current_full_scale_a = 2.0;  // the current channel
  double t_ref_c = 20.0;              // the temperature of the motor file's winding r_ohm
  double shift_fraction = 1.0e-3;     // the requirement's fraction (above)
  bool IsValid(std::string* why) const;
};

// What a recipe is designed from.
struct RecipeBasis {
  std::string motor_id;
  int poles = 0;
  double rotor_inertia_kg_m2 = 0.0;
  analysis::MotionalImpedance nominal;  // the good motor the recipe expects
  double f0_half_soft_hz = 0.0;
  double f0_all_soft_hz = 0.0;
  double residue_to_f0 = 0.0;
  std::string source;  // "the motor's chain", or calibrated to golden units
};

// Throws std::invalid_argument naming the cause (analysis/model/chain_prediction.h).
RecipeBasis BasisFromMotor(const io::MotorSpec& motor);

// The design's values against measured good units: median f0, Q, R, L and residue replace the
// nominal motor (R taken as at t_ref_c), the defect modes move with f0 (the chain's relative
// shifts kept), the direction stays the chain's (good units cannot measure it). One sentence
// per quantity in `disagreements`, "... design X, golden units' median Y (+Z %)", marked
// "DISAGREES" beyond 5 % (f0) or 20 % (the others). Throws std::invalid_argument with fewer than
// 3 units or a unit without one of those measurements (named).
struct Calibration {
  RecipeBasis basis;
  std::vector<std::string> disagreements;
  int units = 0;
};
Calibration CalibrateToGolden(const RecipeBasis& design,
                              const std::vector<analysis::GoldenUnit>& golden);

struct RecipeProposal {
  nlohmann::json recipe;  // validated
  RecipeBasis basis;
  double required_sigma_f0_hz = 0.0;
  analysis::ExcitationCandidate chosen;
  std::vector<std::string> notes;  // each derivation and its rule, one sentence each
};
// Throws std::invalid_argument naming the cause (options, band beyond the sample rate, no
// excitation meeting the requirement) or io::ConfigError (the proposal fails validation).
RecipeProposal ProposeRecipe(const RecipeBasis& basis, const RecipeNewOptions& options,
                             const std::string& recipe_id);

// `recipe` with the designed excitation: its spacing and peak, d.chosen.periods played from
// rest and analysed whole by the transient-aware estimator (transient_frf.h).
Recipe WithDesignedExcitation(Recipe recipe, const analysis::ExcitationDesign& d);

}  // namespace eol::station
