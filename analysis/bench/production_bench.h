// Production benchmark of learned limits (`eol production-bench`).
//
// 1. Draw golden_units good units of the line (line_population.h), measure each with the
//    recipe's excitation (line_measurement.h: the periodic estimate's statistics drawn in the
//    frequency domain), analyse it as the station does (AnalyzeImpedance: weighted ML fit of
//    the clamped motor) and teach limits and a Re Z mask from them (teach.h).
// 2. Draw `units` units at the defect rates, measure and analyse each the same way, and judge
//    it three ways:
//      taught  the recipe's declared measurements with the taught limits and mask (Judge);
//      recipe  the recipe's own limits and masks as given (hand-set);
//      naive   |Z| peak in a fixed window (naive_rule.h).
//    A unit counts as rejected when the verdict is FAIL or ERROR (ERROR is a retest, not a
//    ship). An escape is a defective unit that PASSes; a false reject a good unit that does not.
// 3. Probability of detection (pod.h, MIL-HDBK-1823A hit/miss): for "one magnet" (one soft
//    magnet) and "all magnets" (every magnet soft) pod_units units each, the soft bonds'
//    stiffness loss a drawn uniform on [pod_loss_lo, pod_loss_hi] per unit (stiffness and
//    damping of the good bond times 1 - a, then the line's per-magnet spread), judged by the
//    taught limits (hit: FAIL or ERROR); POD(a) and a90/95 are fitted from those hits.
// Each unit is drawn from (seed, index) alone, so the figures do not depend on the number of
// threads. Golden units use indices from 1e9 up, POD units from 2e9 up, disjoint from the
// production units.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "analysis/bench/naive_rule.h"
#include "analysis/fit/resonance_fit.h"
#include "analysis/progress.h"
#include "analysis/qc/bond_index.h"
#include "analysis/qc/line_population.h"
#include "analysis/qc/pod.h"
#include "analysis/qc/teach.h"
#include "analysis/signal/multisine.h"

namespace eol::analysis {

struct ProductionBenchOptions {
  int units = 10000;
  int golden_units = 50;
  std::uint64_t seed = 1;
  int threads = 2;
  MultisineOptions excitation;  // the recipe's
  std::size_t periods = 4;
  double voltage_noise_v = 2.0e-3;  // the simulated DAQ's, rms per sample
  double current_noise_a = 1.0e-3;
  // The recipe's sequential decision (station/daemon/recipe.h SequentialPolicy; max_extensions 0:
  // none), judged against the taught limits: production units and POD sweeps take further looks
  // of extend_periods periods while a measurement is undecided at confidence_z.
  int max_extensions = 0;
  std::size_t extend_periods = 8;
  double confidence_z = 3.0;
  ResonanceFitOptions fit;                               // the recipe's analysis options
  std::vector<MeasurementSpec> declared;                 // the recipe's scalar limits
  std::vector<CurveMask> recipe_masks;                   // the recipe's masks (the "recipe" rule)
  std::optional<BondIndexDefinition> recipe_bond_index;  // the recipe's (the "recipe" rule)
  TeachOptions teach;
  RotorChainParams rotor;  // nominal geometry, default fixture
  LineSpread spread;
  DefectRates rates;
  NaivePeakRule naive;
  int pod_units = 400;  // per POD sweep (0: none)
  // The sweep is a designed experiment: sizes where POD rises (MIL-HDBK-1823A asks for sizes
  // spanning the transition). Below a loss of 0.8 no limit responds (eol detectability's model
  // POD stays at the false-call level), so units there would only pile up misses.
  double pod_loss_lo = 0.80, pod_loss_hi = 0.99;
  PodOptions pod;
  // Sees the phases "golden units", "production units", "POD one_magnet" and
  // "POD all_magnets" (analysis/progress.h); called from the worker threads.
  ProgressCallback progress;

  bool IsValid(std::string* why) const;
};

struct ClassCounts {
  int units = 0;
  int pass = 0;
  int fail = 0;
  int error = 0;
};

enum class BenchRule { kTaught, kRecipe, kNaive };
inline constexpr std::array<BenchRule, 3> kBenchRules = {BenchRule::kTaught, BenchRule::kRecipe,
                                                         BenchRule::kNaive};
const char* ToString(BenchRule r);

// One POD sweep: the units' defect sizes and hits, their fitted f0 (NaN when the fit was not
// usable), and POD(a).
struct PodSweep {
  std::string name;  // "one_magnet" or "all_magnets"
  DefectClass defect = DefectClass::kOneSoftMagnet;
  std::vector<HitMiss> data;
  std::vector<double> f0_hz;
  PodSummary fit;
};

struct ProductionBenchSummary {
  bool usable = false;
  std::string message;
  TeachSummary teach;
  // counts[rule][class], class in kAllDefectClasses order.
  std::array<std::array<ClassCounts, kAllDefectClasses.size()>, kBenchRules.size()> counts{};
  std::vector<PodSweep> pod;
  // Fitted f0 of every production unit per class (kAllDefectClasses order; usable fits only).
  std::array<std::vector<double>, kAllDefectClasses.size()> f0_hz{};
  // Production units that took more than one look, per class (sequential recipes only).
  std::array<int, kAllDefectClasses.size()> extended{};
  int units = 0;
  double seconds = 0.0;  // wall time of the whole benchmark
  double golden_seconds = 0.0;

  const ClassCounts& Counts(BenchRule rule, DefectClass c) const;
  // Escapes of a defect class (PASS / units), false rejects of good units ((FAIL+ERROR)/units).
  double EscapeRate(BenchRule rule, DefectClass c) const;
  double FalseRejectRate(BenchRule rule) const;
};

ProductionBenchSummary RunProductionBench(const ProductionBenchOptions& options);

}  // namespace eol::analysis
