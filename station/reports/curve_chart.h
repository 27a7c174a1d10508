// The measured impedance against the fitted model and the limits the verdict used, for
// `eol analyze --plot` and `eol query --plot` (drawn with drivers/io/chart.h):
//   top:    |Z| (ohm) over f: measured (markers), fitted model (line on top), the recipe's
//           resonance window [lo, hi] of resonance_f_hz as a shaded band with its edges, the
//           fitted f0, and every |Z| mask (lo and hi bounds as dashed lines);
//   bottom: Re Z (ohm) with the same window and every Re Z mask.
#pragma once

#include <complex>
#include <optional>
#include <string>
#include <vector>

#include "analysis/qc/curve_mask.h"
#include "analysis/qc/measurement.h"
#include "drivers/io/chart.h"

namespace eol::station {

struct CurvePlot {
  std::string title;
  std::vector<double> freq_hz;
  std::vector<std::complex<double>> measured;  // ohm
  std::vector<double> model_freq_hz;
  std::vector<std::complex<double>> model;  // ohm; empty: no fit
  analysis::Limit resonance_window;         // limits of resonance_f_hz (Hz)
  std::optional<double> f0_hz;              // fitted
  std::vector<analysis::CurveMask> masks;
  std::vector<std::string> notes;  // e.g. the verdict, or why masks are not drawn
};

io::Chart CurveChart(const CurvePlot& plot);

}  // namespace eol::station
