// The one judge: the verdict of a unit from the recipe and what was measured, used by the
// sequencer (station/daemon/sequencer.h) on the station and by `eol analyze --recipe` offline, so a
// recording gets the same verdict and reasons wherever it is judged.
//
// Per phase pair, in the recipe's order:
//   1. analysis not usable                 -> ERROR, reason "analysis" (the analysis's message),
//                                             or "clipped" when a channel reached the DAQ's
//                                             range (analysis/signal/clipping.h); nothing else
//                                             is judged for that pair.
//   2. scalar limits (recipe "limits")     -> FAIL "limit" outside; ERROR "analysis" when a
//                                             declared value is missing or not finite.
//                                             bond_index_pct is computed here from f0 and the
//                                             residue when the recipe has "bond_index";
//                                             resonance_f_ref_pressure_hz from f0 and
//                                             conditions.clamp_pressure_bar when it has
//                                             "f0_pressure" (without a pressure: ERROR, and a
//                                             reason that says where it comes from).
//   3. curve masks (recipe "masks")        -> the count of lines outside is a measurement
//                                             mask_<name>_lines_outside judged against
//                                             max_lines_outside (FAIL "mask"); when the pair
//                                             FAILs, one more "mask" reason per mask exceeded
//                                             names its worst line.
//   4. conditions (station/daemon/conditions.h)   -> with out_of_window "error", any condition out
//   of
//                                             its window makes the pair ERROR "condition" (the
//                                             limits assume those conditions); those reasons
//                                             come first.
// Pairs are merged with analysis::Worse(). The first pair's measurements keep their names;
// a further pair's are named "<name>@<pair>" ("resonance_f_hz@V-W") and its reasons start
// with "phase pair V-W: ". Reasons are ordered: first pair (conditions, limits, masks), then
// each further pair.
//
// Without a recording of the recipe's excitation (an FRF file judged offline, or a noise
// recording analysed with Welch) the excitation-level conditions cannot be evaluated: they are
// listed in Judgement::conditions_not_evaluated and do not change the outcome (the winding
// temperature, estimated from the fitted R, is still judged).
#pragma once

#include <span>
#include <string>
#include <vector>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/measurement.h"
#include "analysis/signal/recording.h"
#include "db/test_conditions.h"
#include "drivers/fixture/fixture.h"
#include "station/daemon/recipe.h"

namespace eol::station {

// "U-V", "V-W", "W-U": the suffix of a further pair's measurement and curve names.
const char* PairName(drivers::PhasePair pair);

struct PairMeasurement {
  drivers::PhasePair pair = drivers::PhasePair::kUV;
  const analysis::ImpedanceAnalysis* analysis = nullptr;  // never null
  const analysis::Recording* recording = nullptr;         // null: an FRF judged offline
};

struct Judgement {
  analysis::Outcome outcome = analysis::Outcome::kError;
  std::vector<analysis::Measurement> measurements;
  std::vector<analysis::Reason> reasons;              // empty for a clean PASS
  std::vector<analysis::Outcome> pair_outcomes;       // one per PairMeasurement, same order
  std::vector<std::string> conditions_not_evaluated;  // condition names, see above
};

// Judges the unit. `pairs` must not be empty (a programmer error otherwise). Reads
// conditions.clamp_pressure_bar; writes each pair's evaluated conditions into `conditions`
// (station/daemon/conditions.h; a later pair overwrites an earlier one's values) and, when the
// recipe has a "conditions" section, conditions_in_window true only when every pair's conditions
// were inside their windows.
Judgement JudgeUnit(const Recipe& recipe, std::span<const PairMeasurement> pairs,
                    db::TestConditions& conditions);

}  // namespace eol::station
