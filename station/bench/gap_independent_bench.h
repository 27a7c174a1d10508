// `eol gap-bench --independent DIR`: the gap diagnosis on the blind cases of the independent
// generators (tests/peers/independent_gap_cases.py, independent_tolerance_cases.py; written
// from the physics in numpy, no code shared with analysis/). Each case of DIR/truth.json is
// read and diagnosed as `eol gap --sim case-NNN-sim.csv --measured case-NNN-meas.csv` does
// (station/reports/gap_diagnosis.h), with the sigma's degrees of freedom the truth states, and
// scored without the label being seen by the diagnosis:
//   class none    (no hidden effect; with calibration offsets: calibration only): right when
//                 `none`; a pair answered is counted apart (the issue-38 rule: never a pair);
//   class single  right when the answer is the one effect alone (EXPECTED: a fractional
//                 inductance and an eddy branch count as either lossy_inductance or
//                 fractional_inductance, a fixture spring as fixture_compliance);
//   class pair    right when the answer names exactly the two effects.
// "separable" is the generator's (truth.json; its oracle: independent_tolerance_cases.py).
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace eol::station {

struct IndependentGapCase {
  std::string name;
  std::string cls;     // "none", "single", "pair"
  std::string hidden;  // the generator's effect names joined with "+", or "none"
  bool separable = true;
  double strength = 0.0;
  std::string answer;  // the diagnosis, or "error: ..."
  bool right = false;
  bool pair_answered = false;
};

struct IndependentGapClass {
  int cases = 0, right = 0, separable = 0, separable_right = 0, pair_answered = 0;
};

struct IndependentGapSummary {
  std::vector<IndependentGapCase> cases;
  IndependentGapClass none, single, pair;
  double seconds = 0.0;
};

// True when `answer` names exactly the generator's effects `hidden` ("a" or "a+b").
bool NamesExactly(const std::string& answer, const std::string& hidden);

// Throws io::FileError / io::ConfigError for an unreadable DIR/truth.json; a case whose files
// cannot be diagnosed is scored as an error answer.
IndependentGapSummary RunIndependentGapCases(
    const std::string& dir, const std::function<void(const IndependentGapCase&)>& on_case);

}  // namespace eol::station
