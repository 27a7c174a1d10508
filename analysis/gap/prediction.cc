#include "analysis/gap/prediction.h"

#include <cmath>
#include <sstream>

#include "analysis/fit/resonance_fit.h"

namespace eol::analysis {
namespace {

std::vector<AppliedEffect> Transfer(const NominalNetwork& n1, const std::vector<AppliedEffect>& e,
                                    const NominalNetwork& n2) {
  std::vector<AppliedEffect> out = e;
  for (AppliedEffect& a : out) {
    if (a.kind != EffectKind::kFixtureCompliance || a.params.empty()) continue;
    const double k1 = n1.NominalStiffnessNmPerRad(), k2 = n2.NominalStiffnessNmPerRad();
    const double ratio =
        k1 > 0.0 && k2 > 0.0 ? k1 / k2 : std::pow(n1.motional.f0_hz / n2.motional.f0_hz, 2.0);
    a.params[0] *= ratio;
  }
  return out;
}

bool ResonanceOf(const Frf& z, double* f0, double* q) {
  const FitSummary fit = FitMotionalResonance(z, ResonanceFitOptions{});
  if (!fit.usable) return false;
  *f0 = fit.Model().f0_hz;
  *q = fit.Model().q;
  return true;
}

}  // namespace

PredictionSummary PredictWithEffects(const NominalNetwork& n1, const RankedEffect& fitted,
                                     const NominalNetwork& n2, const std::vector<double>& freq_hz) {
  PredictionSummary s;
  std::string why;
  if (!n1.IsValid(&why) || !n2.IsValid(&why)) {
    s.message = "invalid nominal: " + why;
    return s;
  }
  if (n1.quantity != n2.quantity) {
    s.message = "the two simulations are of different quantities";
    return s;
  }
  s.effects = Transfer(n1, fitted.effects, n2);
  s.predicted = EvaluateNetwork(n2, s.effects, freq_hz);
  if (n2.quantity != Quantity::kImpedanceOhm) {
    s.usable = true;
    s.message = "predicted response of the second simulation in the measured set-up";
    return s;
  }
  s.f0_simulated_hz = n2.motional.f0_hz;
  double q = 0.0;
  if (!ResonanceOf(s.predicted, &s.f0_predicted_hz, &q)) {
    s.message = "no resonance in the predicted response between " +
                std::to_string(freq_hz.front()) + " and " + std::to_string(freq_hz.back()) + " Hz";
    return s;
  }
  s.q_predicted = q;
  // One sigma per fitted parameter, in the order of fitted.params (fitted ones come first).
  double var = 0.0;
  std::size_t index = 0;
  for (std::size_t e = 0; e < fitted.effects.size(); ++e) {
    for (std::size_t p = 0; p < fitted.effects[e].params.size(); ++p, ++index) {
      if (index >= fitted.params.size()) break;
      const double sigma = fitted.params[index].sigma;
      if (!(std::isfinite(sigma) && sigma > 0.0)) continue;
      std::vector<AppliedEffect> moved = fitted.effects;
      moved[e].params[p] += sigma;
      double f0 = 0.0, q_moved = 0.0;
      if (ResonanceOf(EvaluateNetwork(n2, Transfer(n1, moved, n2), freq_hz), &f0, &q_moved))
        var += (f0 - s.f0_predicted_hz) * (f0 - s.f0_predicted_hz);
    }
  }
  s.sigma_f0_hz = std::sqrt(var);
  std::ostringstream os;
  os.precision(5);
  os << "the second simulation rings at " << s.f0_simulated_hz << " Hz; with the diagnosed "
     << (fitted.effect.empty() ? "gap" : fitted.effect) << " it rings at " << s.f0_predicted_hz
     << " +- " << s.sigma_f0_hz << " Hz (Q " << s.q_predicted << ")";
  s.message = os.str();
  s.usable = true;
  return s;
}

}  // namespace eol::analysis
