#include "station/daemon/judge.h"

#include <cmath>
#include <map>
#include <optional>
#include <stdexcept>

#include "analysis/qc/curve_mask.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"
#include "station/daemon/conditions.h"

namespace eol::station {
namespace {

using analysis::Fixed;
using analysis::Outcome;
using analysis::Reason;
using analysis::ReasonCode;

struct PairJudgement {
  Outcome outcome = Outcome::kError;
  std::vector<analysis::Measurement> measurements;
  std::vector<Reason> reasons;
};

PairJudgement JudgePair(const Recipe& recipe, const PairMeasurement& p,
                        db::TestConditions& conditions, bool& conditions_in_window,
                        std::vector<std::string>& not_evaluated) {
  const analysis::ImpedanceAnalysis& a = *p.analysis;
  PairJudgement j;
  if (!a.usable) {
    j.outcome = Outcome::kError;
    j.reasons.push_back({a.frf.clipped ? ReasonCode::kClipped : ReasonCode::kAnalysis, a.message});
    return j;
  }
  std::map<std::string, analysis::Estimate> values = a.values;
  const std::optional<double> clamp_pressure_bar = conditions.clamp_pressure_bar;
  if (recipe.f0_pressure)
    analysis::AddF0AtRefPressure(values, clamp_pressure_bar, *recipe.f0_pressure);
  if (recipe.bond_index) analysis::AddBondIndex(values, *recipe.bond_index);  // may weigh it
  std::vector<analysis::MeasurementSpec> mask_specs;
  std::vector<Reason> mask_details;
  for (const analysis::CurveMask& mask : recipe.masks) {
    const analysis::MaskCheck c = analysis::CheckMask(a.frf.frf, mask);
    values[mask.MeasurementName()] = {static_cast<double>(c.lines_outside), std::nan("")};
    mask_specs.push_back(mask.Spec());
    if (c.lines_outside > mask.max_lines_outside)
      mask_details.push_back(
          {ReasonCode::kMask, "mask " + mask.name + ": worst line " + Fixed(c.worst_f_hz, 1) +
                                  " Hz, " + Fixed(c.worst_excess, 3) + " ohm beyond the bound"});
  }
  const analysis::Verdict limits = analysis::Judge(recipe.limits, values);
  const analysis::Verdict masks = analysis::Judge(mask_specs, values, ReasonCode::kMask);
  j.outcome = analysis::Worse(limits.outcome, masks.outcome);
  j.measurements = limits.measurements;
  j.measurements.insert(j.measurements.end(), masks.measurements.begin(), masks.measurements.end());
  j.reasons = limits.reasons;
  if (recipe.f0_pressure && !clamp_pressure_bar)
    j.reasons.push_back(
        {ReasonCode::kAnalysis, std::string(analysis::names::kResonanceFRefPressureHz) +
                                    " needs the clamp pressure read at clamp confirmation "
                                    "(conditions.clamp_pressure_bar; offline: eol analyze "
                                    "--clamp-pressure-bar P)"});
  j.reasons.insert(j.reasons.end(), masks.reasons.begin(), masks.reasons.end());
  if (j.outcome == Outcome::kFail)
    j.reasons.insert(j.reasons.end(), mask_details.begin(), mask_details.end());

  std::optional<double> r_ohm;
  if (const auto it = values.find(std::string(analysis::names::kWindingROhm)); it != values.end())
    r_ohm = it->second.value;
  std::vector<std::string> skipped;
  const std::vector<std::string> off = EvaluateConditions(
      recipe.conditions, p.recording, recipe.transient_periods, r_ohm, conditions, &skipped);
  for (const std::string& name : skipped) {
    bool seen = false;
    for (const std::string& s : not_evaluated) seen = seen || s == name;
    if (!seen) not_evaluated.push_back(name);
  }
  if (!off.empty()) conditions_in_window = false;
  if (!off.empty() && recipe.conditions.error_when_out) {
    // The limits assume the recipe's conditions: the station did not measure this motor.
    j.outcome = Outcome::kError;
    std::vector<Reason> reasons;
    for (const std::string& line : off)
      reasons.push_back({ReasonCode::kCondition, "condition out of window: " + line});
    reasons.insert(reasons.end(), j.reasons.begin(), j.reasons.end());
    j.reasons = std::move(reasons);
  }
  return j;
}

}  // namespace

const char* PairName(drivers::PhasePair pair) {
  switch (pair) {
    case drivers::PhasePair::kUV:
      return "U-V";
    case drivers::PhasePair::kVW:
      return "V-W";
    case drivers::PhasePair::kWU:
      return "W-U";
  }
  return "?";
}

Judgement JudgeUnit(const Recipe& recipe, std::span<const PairMeasurement> pairs,
                    db::TestConditions& conditions) {
  if (pairs.empty()) throw std::logic_error("JudgeUnit: no phase pair to judge");
  Judgement out;
  bool in_window = true;
  for (std::size_t k = 0; k < pairs.size(); ++k) {
    if (pairs[k].analysis == nullptr) throw std::logic_error("JudgeUnit: a pair has no analysis");
    PairJudgement j =
        JudgePair(recipe, pairs[k], conditions, in_window, out.conditions_not_evaluated);
    out.outcome = k == 0 ? j.outcome : analysis::Worse(out.outcome, j.outcome);
    out.pair_outcomes.push_back(j.outcome);
    const std::string suffix = k == 0 ? "" : std::string("@") + PairName(pairs[k].pair);
    const std::string prefix =
        k == 0 ? "" : std::string("phase pair ") + PairName(pairs[k].pair) + ": ";
    for (analysis::Measurement& m : j.measurements) {
      m.name += suffix;
      out.measurements.push_back(std::move(m));
    }
    for (Reason& r : j.reasons) out.reasons.push_back({r.code, prefix + r.text});
  }
  if (recipe.conditions.enabled) conditions.conditions_in_window = in_window;
  return out;
}

}  // namespace eol::station
