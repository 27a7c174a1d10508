// The report of `eol gap`: text for people and JSON for programs.
//
// JSON (stable names, SI units; NaN is written as null):
//   quantity            "impedance" | "mobility"
//   effect              the winner: an effect name, "a+b" for a pair, "none" (the nominal
//                       calibrated within the design's tolerances is consistent with the
//                       noise), "calibration_beyond_tolerance" (only a calibration beyond them
//                       is) or "unexplained" (not noise, but no candidate explains it)
//   effects             the winner's effect names (empty for none / unexplained)
//   rival, rival_score_gap  another effect (as many members) whose evidence is within 4.6 of
//                       the winner's (score minus the winner's): the data hardly tell them
//                       apart; "" and null when there is none
//   params              the winner's parameters {name: value} (fitted, then derived)
//   gap_before, gap_after        g = sqrt(mean |H_meas - H_model|^2 / sigma^2) over all lines
//   chi2_before, chi2_after, residuals (2K), noise_z_before, noise_z_after (noise test z,
//   residual.h), sigma_scale (sqrt(mean |r|^2 / E|r|^2) of the nominal)
//   heldout             {gap_before, gap_after, method}: "interleaved-2fold",
//                       "leave-one-unit-out" or "none"
//   where               [{f_lo_hz, f_hi_hz, significance, gap_before, gap_after}] bands of the
//                       nominal's normalised residual, most significant first; significance
//                       is the Gaussian-equivalent z of the band's chi2 (residual.h)
//   where_after         the bands that remain after the winner
//   ranking             [{effect, params {name: value}, params_sigma {name: sigma}, score
//                       (cost + Laplace Occam penalty: which effect), bic (cost + p ln(2K):
//                       whether an effect), cost (-2 ln L), gap_after, plausible, rejected}],
//                       best first, "none" included
//   residual_form       "impedance", "admittance" or "mixed" (effect_fit.h ChooseResidualForm)
//   residual_admittance_hz  per measured unit, the lines (Hz) in admittance form where its
//                       form is mixed (empty otherwise)
//   features            [{measurement, name, simulated, measured, gap, sigma, significance}]
//                       names f0_hz, q, peak_height_ohm, r_ohm, l_h (impedance) or
//                       gain_rad_per_s2_per_a, damping_per_s (mobility)
//   calibration         {simulation, kind, note, params {name: {value, sigma}},
//                       misfit_rel_rms, inertia_kg_m2, inertia_source}: the nominal fitted to the
//                       simulation; inertia_source says where J_r came from (GapReport)
//   refit               [{measurement, params {name: {value, sigma}}, gap_after_refit}]: the
//                       nominal refitted to each measurement (not an unmodelled effect)
//   rivals              [{effect, score_gap, note}]: every rival answer with its evidence
//                       (score minus the answer's) and why it is not the answer (a pair
//                       rejected: which member is not significant, by how much)
//   tolerances          {r, l, torque_constant, inertia, stiffness, damping, daq_gain, source}:
//                       the prior's sds (damping a factor) and "default" | "simulation" |
//                       "given"; calibrate false when the nominal was kept fixed
//   calibration_offsets {name: {offset, tolerances}}: the physical offsets (r, l,
//                       torque_constant, inertia, stiffness, damping, daq_gain; relative, and in
//                       tolerances) the answer's calibration within the tolerances implies
//                       (analysis/gap/tolerance.h); {} when the nominal is kept fixed
//   beyond_tolerance    {found, g, cost_gain, offsets}: the nominal calibrated with no prior
//                       (diagnosis.h CalibrationFinding); found: -2 ln L at least 10 lower than
//                       within the tolerances and a parameter at 2 or more tolerances
//   split               calibration and structure apart (diagnosis.h GapSplit): three ways
//                       {g_within_tolerance, g_structure, g_beyond_tolerance,
//                       share_within_tolerance, share_structure_within_tolerance,
//                       share_left_within_tolerance, share_beyond_tolerance,
//                       heldout_g_within_tolerance, heldout_g_structure,
//                       heldout_g_beyond_tolerance}, and as before issue 38 {g_nominal,
//                       g_refit, g_refit_effect, share_calibration, share_structure,
//                       share_left, heldout_g_nominal, heldout_g_refit_effect, heldout_method,
//                       refit {R_ohm, L_h, Rp_ohm, f0_hz, Q | gain_rad_per_s2_per_a,
//                       damping_per_s}, refit_effect {...}, effect [{effect, params}]}
//   measurements        [{source, kind, note, lines, sigma_estimated, gap_before, gap_after}]
//   sigma_pool_lines    the --sigma-pool half-width used (0: the files' sigma as given)
//   sigma_dof           degrees of freedom of each line's sigma^2 after pooling (0: exact)
//   prediction          (with --predict-sim) {simulation, f0_simulated_hz, f0_predicted_hz,
//                       sigma_f0_hz, q_predicted, effects [{effect, params}], message}
//   score_rule, message
// Effect parameter names: effects.h (k_fixture_ratio, fixture_loss_factor,
// k_fixture_nm_per_rad, f_loaded_hz, delay_s, capacitance_f, resistance_ohm, l2_h, r2_ohm,
// corner_hz, skin_r_rise_at_1khz, f_hz, q, height_ohm | height_rad_per_s_per_a, creep_lambda).
#pragma once

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/gap/calibration.h"
#include "analysis/gap/diagnosis.h"
#include "analysis/gap/features.h"
#include "analysis/gap/prediction.h"
#include "drivers/io/gap_inputs.h"

namespace eol::station {

struct GapPrediction {
  io::GapInput simulation;
  analysis::CalibrationSummary calibration;
  analysis::PredictionSummary prediction;
};

struct GapReport {
  analysis::Quantity quantity = analysis::Quantity::kImpedanceOhm;
  io::GapInput simulation;
  analysis::CalibrationSummary calibration;
  std::vector<io::GapInput> measured;
  int sigma_pool = 0;
  double sigma_dof = 0.0;
  double inertia_kg_m2 = 0.0;  // J_r the calibration used (0: unknown)
  // Where J_r came from: "given" (--inertia), "simulation" (its motor file), "recipe" (the
  // recipe's rotor, assumed because the simulation names none: meaningless for another
  // machine) or "" (unknown).
  std::string inertia_source;
  // The design's tolerances the nominal was calibrated under, and where they came from:
  // "default", "simulation" (its motor JSON) or "given" (--tolerances).
  analysis::NominalTolerances tolerances;
  std::string tolerance_source = "default";
  analysis::GapSummary gap;
  std::vector<analysis::FeatureSummary> features;  // per measured unit
  std::optional<GapPrediction> prediction;
};

// The ranking entry of the winner, or nullptr for none / unexplained.
const analysis::RankedEffect* Winner(const analysis::GapSummary& gap);

nlohmann::json GapReportJson(const GapReport& report);
std::string GapReportText(const GapReport& report);

}  // namespace eol::station
