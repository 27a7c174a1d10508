#include "analysis/impedance_analysis.h"

#include <algorithm>
#include <cmath>

#include "analysis/fit/modes_fit.h"
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

// The likelihood-ratio statistic for a second motional mode: chi2 of the one-mode fit minus
// that of the best two-mode fit (modes_fit.h, its residual search over the whole (f, Q) grid,
// whether or not the second mode passes the order selection). Without a second mode it
// scatters as the maximum over the grid of a three-parameter chi2 drop (about 11 median, 30
// at 99.9 % on the line model's good units with 601 lines); a soft magnet's local mode gives
// its whole noncentrality at once, where chi2/dof spreads it over every line.
Estimate SecondModeChi2Drop(const Frf& z, const ResonanceFitOptions& options, double chi2_one) {
  ModesFitOptions m;
  m.single = options;
  m.single.second_mode_test = false;
  m.max_modes = 2;
  const ModesFitSummary s = FitMotionalModes(z, m);
  for (const ModeOrderCandidate& c : s.candidates)
    if (c.modes == 2 && std::isfinite(c.chi2) && c.chi2 > 0.0)
      return Estimate{std::max(0.0, chi2_one - c.chi2), std::nan("")};
  return Estimate{0.0, std::nan("")};  // no two-mode start anywhere: nothing to add
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
  if (options.second_mode_test)
    a.values[std::string(names::kSecondModeChi2Drop)] = SecondModeChi2Drop(z, options, a.fit.chi2);
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
