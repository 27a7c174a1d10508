#include "analysis/impedance_analysis.h"

#include <cmath>

#include "analysis/qc/measurement_names.h"

namespace eol::analysis {
namespace {

void AddValue(ImpedanceAnalysis& a, std::string_view measurement, const char* param) {
  if (const FittedParameter* p = a.fit.Find(param))
    a.values[std::string(measurement)] = Estimate{p->value, p->sigma};
}

}  // namespace

ImpedanceAnalysis AnalyzeImpedance(const Frf& z, const ResonanceFitOptions& options) {
  ImpedanceAnalysis a;
  a.frf.frf = z;
  a.frf.usable = true;
  a.fit = FitMotionalResonance(z, options);
  if (!a.fit.usable) {
    a.message = "fit not usable: " + a.fit.message;
    return a;
  }
  AddValue(a, names::kResonanceFHz, "f0_hz");
  AddValue(a, names::kResonanceQ, "Q");
  AddValue(a, names::kWindingROhm, "R_ohm");
  AddValue(a, names::kWindingLH, "L_h");
  AddValue(a, names::kMotionalRpOhm, "Rp_ohm");
  a.values[std::string(names::kFitChi2PerDof)] = Estimate{a.fit.chi2_per_dof, std::nan("")};
  a.usable = true;
  a.message = a.fit.message;
  return a;
}

ImpedanceAnalysis AnalyzeRecording(const Recording& recording,
                                   const std::vector<std::size_t>& lines,
                                   const ImpedanceAnalysisOptions& options) {
  const FrfSummary frf = options.frf_method == FrfMethod::kTransientLpm
                             ? EstimateTransientFrf(recording, lines, options.lpm)
                             : EstimatePeriodicFrf(recording, lines, options.frf);
  if (!frf.usable) {
    ImpedanceAnalysis a;
    a.frf = frf;
    a.message = "invalid measurement: " + frf.message;
    return a;
  }
  ImpedanceAnalysis a = AnalyzeImpedance(frf.frf, options.fit);
  a.frf = frf;
  return a;
}

}  // namespace eol::analysis
