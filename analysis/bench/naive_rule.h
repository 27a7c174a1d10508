// The naive production rule the benchmark compares against: find the motional peak as the
// largest local excess of |Z| over a straight line fitted to |Z| in a search band, refine it
// with a parabola through the peak line and its neighbours, and pass the unit when that
// frequency lies in a fixed window. This is what a hand-tuned station does without a model:
// |Z| peak-picking is biased low by the inductive background (analysis/README.md 2: 387.6 Hz for a
// 390 Hz mode) and the window is set once by hand, not learned.
#pragma once

#include <optional>

#include "analysis/frf.h"

namespace eol::analysis {

struct NaivePeakRule {
  double search_lo_hz = 250.0;
  double search_hi_hz = 700.0;
  double window_lo_hz = 370.0;
  double window_hi_hz = 420.0;

  bool IsValid(std::string* why) const;
};

// The peak frequency, or nullopt when the band holds fewer than 3 lines.
std::optional<double> NaivePeakHz(const Frf& z, const NaivePeakRule& rule);
// True when the peak is found and inside [window_lo_hz, window_hi_hz].
bool NaivePass(const Frf& z, const NaivePeakRule& rule);

}  // namespace eol::analysis
