#include "analysis/impedance_analysis.h"

#include <cmath>

#include "analysis/qc/measurement_names.h"

namespace eol::analysis {
namespace {

void AddValue(ImpedanceAnalysis& a, std::string_view measurement, const char* param) {
  if (const FittedParameter* p = a.fit.Find(param))
    a.values[std::string(measurement)] = Estimate{p->value, p->sigma};
}

// Residue T^2 / J = Rp w0 / Q with its standard uncertainty by the delta method over the
// fit's covariance: d ln A = d ln Rp + d ln f0 - d ln Q.
Estimate Residue(const FitSummary& fit) {
  const double value = fit.Model().ResidueOhmPerS();
  const std::pair<const char*, double> terms[] = {{"Rp_ohm", 1.0}, {"f0_hz", 1.0}, {"Q", -1.0}};
  Eigen::VectorXd gradient = Eigen::VectorXd::Zero(fit.covariance.rows());
  for (const auto& [name, power] : terms) {
    std::size_t i = 0;
    while (i < fit.params.size() && fit.params[i].name != name) ++i;
    if (i >= fit.params.size() || static_cast<Eigen::Index>(i) >= gradient.size())
      return Estimate{value, std::nan("")};
    gradient(static_cast<Eigen::Index>(i)) = power * value / fit.params[i].value;
  }
  return Estimate{value, std::sqrt(gradient.dot(fit.covariance * gradient))};
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
  a.values[std::string(names::kMotionalResidueOhmPerS)] = Residue(a.fit);
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
