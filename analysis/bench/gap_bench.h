// Blind benchmark of the gap diagnosis (`eol gap-bench`): cases drawn from the project's
// simulator with one hidden effect (or none), diagnosed without the label, scored.
//
// A case:
//   nominal   a unit drawn from analysis::MotorPopulation (spreads included), poorly cemented
//             with probability defect_share, with a rigid fixture with probability rigid_share
//             (so the nominal rings near 706, 529, 390 or 350 Hz);
//   truth     one of "none" and the eight effects of effects.h, uniformly; the effect's shape
//             parameters are drawn at random (second_mode: f in the band, at least 4 % from
//             f0, q log-uniform in [10, 300]; lossy_inductance: corner log-uniform in
//             [0.5 f_lo, 5 f_hi]; fixture_compliance: loss 0.6-1.6 times the one that keeps
//             Q; signs of resistance and delay random) and its strength parameter is solved
//             so that the effect alone moves the measurement by
//               S = sqrt(sum_k 2 |H_true - H_nominal|^2 / sigma_k^2)
//             (sigma_k the expected per-line sigma, measurement_sim.h), S log-uniform in
//             [strength_lo, strength_hi]: detectable (S^2 far above the BIC penalty) but
//             often weak; S >= strong_strength is "strong";
//   measured  the recipe's multisine through the simulator with the DAQ noise scaled by a
//             random factor in [noise_scale_lo, noise_scale_hi] (measurement_sim.h; the
//             periodic estimator pools the noise spectra over +-5 lines), optionally pooled
//             further over +-sigma_pool lines (noise.h);
//   simulated the nominal's noise-free FRF on the same lines, calibrated like `eol gap` does.
// Scores:
//   top-1        diagnosed name == truth (a pair or "unexplained" is wrong);
//   oracle       a case is separable when an oracle that knows the true family and starts
//                its fit at the true parameters finds it scores (the diagnosis' score: cost
//                + Occam penalty - 2 ln prior odds, diagnosis.h; "none": its cost) at least
//                oracle_margin below every other plausible single effect the diagnosis fitted and
//                below "none". Every "none" case counts as separable (the diagnosis must never
//                invent an effect from noise), so top-1 on separable cases is strict there;
//   band         the most significant reported band overlaps the lines where the hidden effect
//                acts (|dH_k| / sigma_k at least a quarter of its maximum);
//   held out     g on held-out lines after / before the fix (diagnosis.h), and the share of
//                the held-out excess it explains, (g_b^2 - g_a^2) / (g_b^2 - 1), for cases
//                with a hidden effect that was named correctly;
//   none-strong  cases with S >= strong_strength diagnosed "none" (target: 0).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "analysis/gap/diagnosis.h"
#include "analysis/signal/multisine.h"
#include "analysis/sim/measurement_sim.h"
#include "analysis/sim/population.h"

namespace eol::analysis {

struct GapBenchOptions {
  int cases = 200;
  std::uint64_t seed = 1;
  MotorPopulation population;
  double defect_share = 0.3;
  double rigid_share = 0.5;
  MultisineOptions excitation;  // the recipe's: 200-800 Hz, 1 Hz, 8 kHz, 2 V
  SimulatedMeasurementOptions measurement;
  double noise_scale_lo = 0.5;
  double noise_scale_hi = 3.0;
  double strength_lo = 6.0;
  double strength_hi = 150.0;
  double strong_strength = 20.0;
  double oracle_margin = 10.0;
  int sigma_pool = 0;  // extra pooling (noise.h); the periodic estimator already pools
  // The simulation is each unit's own nominal (exact): the nominal is kept at its values, as
  // the figures were measured (analysis/gap/README.md); the calibrated diagnosis of issue 38
  // is benchmarked on the independent tolerance cases (`eol gap-bench --independent`).
  GapOptions gap = [] {
    GapOptions g;
    g.calibrate = false;
    return g;
  }();

  bool IsValid(std::string* why) const;
};

struct GapBenchCase {
  int index = 0;
  std::string truth;  // "none" or an effect name
  std::vector<double> truth_params;
  double strength = 0.0;  // S (0 for none)
  bool strong = false;
  double nominal_f0_hz = 0.0;
  std::string diagnosed;
  bool correct = false;
  bool oracle_separable = false;
  bool band_reported = false;
  bool band_covers = false;
  double gap_before = 0.0, gap_after = 0.0;
  double heldout_before = 0.0, heldout_after = 0.0;
};

struct GapBenchSummary {
  bool usable = false;
  std::string message;
  std::vector<GapBenchCase> cases;
  std::vector<std::string> truth_labels;      // rows: "none" and the eight effects
  std::vector<std::string> diagnosed_labels;  // columns: the same, "pair", "unexplained"
  std::vector<std::vector<int>> confusion;    // [row][column] counts
  double top1 = 0.0;
  double top1_separable = 0.0;
  int separable = 0;
  double band_coverage = 0.0;  // over band_cases
  int band_cases = 0;          // cases with an effect and a reported band
  int effect_cases_without_band = 0;
  double median_heldout_shrink = 0.0;  // heldout g after / before
  // Share of the held-out excess explained, (g_before^2 - g_after^2) / (g_before^2 - 1).
  double median_heldout_excess_explained = 0.0;
  double median_heldout_after = 0.0;
  double p90_heldout_after = 0.0;
  double heldout_within_1_3 = 0.0;  // share of those cases with held-out g after <= 1.3
  int heldout_cases = 0;
  int strong_cases = 0;
  int none_for_strong = 0;
  int errors = 0;  // cases the simulator or the diagnosis could not run (counted unexplained)
};

// One case alone (the same as case `index` of RunGapBench); *detail, when given, gets the
// diagnosis of that case.
GapBenchCase RunGapBenchCase(const GapBenchOptions& options, int index,
                             GapSummary* detail = nullptr);

// Runs every case in order; `progress` (may be empty) sees each finished case.
GapBenchSummary RunGapBench(const GapBenchOptions& options,
                            const std::function<void(const GapBenchCase&)>& progress = {});

}  // namespace eol::analysis
