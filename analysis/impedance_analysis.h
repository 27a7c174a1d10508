// The analysis every test runs: recording -> Z(f) with sigma -> physical fit -> named
// measurements with uncertainties. Pure computation; the station and the offline commands
// call the same functions.
#pragma once

#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/fit/resonance_fit.h"
#include "analysis/qc/measurement.h"
#include "analysis/signal/frf_method.h"
#include "analysis/signal/periodic_frf.h"
#include "analysis/signal/recording.h"
#include "analysis/signal/transient_frf.h"

namespace eol::analysis {

struct ImpedanceAnalysisOptions {
  FrfMethod frf_method = FrfMethod::kDiscardTransient;
  PeriodicFrfOptions frf;   // kDiscardTransient
  TransientFrfOptions lpm;  // kTransientLpm
  ResonanceFitOptions fit;
};

struct ImpedanceAnalysis {
  bool usable = false;
  std::string message;  // why not usable, or a one-line summary
  FrfSummary frf;
  FitSummary fit;
  // Named measurements (analysis/qc/measurement_names.h) with their standard uncertainties.
  std::map<std::string, Estimate> values;
};

ImpedanceAnalysis AnalyzeRecording(const Recording& recording,
                                   const std::vector<std::size_t>& lines,
                                   const ImpedanceAnalysisOptions& options);
// From an impedance already estimated (files, re-analysis).
ImpedanceAnalysis AnalyzeImpedance(const Frf& z, const ResonanceFitOptions& options);

}  // namespace eol::analysis
