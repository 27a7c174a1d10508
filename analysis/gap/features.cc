#include "analysis/gap/features.h"

#include <cmath>
#include <map>

namespace eol::analysis {

FeatureSummary CompareFeatures(const CalibrationSummary& sim, const GapUnit& meas,
                               Quantity quantity, const CalibrationOptions& options) {
  FeatureSummary s;
  Frf h;
  h.freq_hz = meas.freq_hz;
  h.value = meas.value;
  h.sigma = meas.sigma;
  h.quantity = quantity;
  h.method = "measured";
  s.refit = CalibrateNominal(h, options);
  if (!s.refit.usable) {
    s.message = "the nominal could not be refitted to the measurement: " + s.refit.message;
    return s;
  }
  double chi2 = 0.0;
  for (std::size_t k = 0; k < meas.size(); ++k)
    chi2 += std::norm(meas.value[k] - s.refit.nominal.At(meas.freq_hz[k])) /
            (meas.sigma[k] * meas.sigma[k]);
  s.gap_after_refit = std::sqrt(chi2 / static_cast<double>(meas.size()));
  // Fit parameter name -> stable feature name.
  static const std::map<std::string, std::string> kNames = {
      {"f0_hz", "f0_hz"},
      {"Q", "q"},
      {"Rp_ohm", "peak_height_ohm"},
      {"R_ohm", "r_ohm"},
      {"L_h", "l_h"},
      {"gain_rad_per_s2_per_a", "gain_rad_per_s2_per_a"},
      {"damping_per_s", "damping_per_s"}};
  for (const FittedParameter& m : s.refit.params) {
    const auto name = kNames.find(m.name);
    if (name == kNames.end()) continue;
    const FittedParameter* ref = nullptr;
    for (const FittedParameter& p : sim.params)
      if (p.name == m.name) ref = &p;
    if (!ref) continue;
    FeatureGap f;
    f.name = name->second;
    f.unit = m.unit;
    f.simulated = ref->value;
    f.measured = m.value;
    f.gap = m.value - ref->value;
    const double s_sim = std::isfinite(ref->sigma) ? ref->sigma : 0.0;
    f.sigma = std::sqrt(m.sigma * m.sigma + s_sim * s_sim);
    f.significance = f.sigma > 0.0 ? f.gap / f.sigma : 0.0;
    s.features.push_back(f);
  }
  s.usable = true;
  s.message = "nominal refitted to the measurement: g " + std::to_string(s.gap_after_refit);
  return s;
}

}  // namespace eol::analysis
