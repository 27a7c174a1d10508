#include "analysis/qc/f0_pressure.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "analysis/qc/measurement_names.h"
#include "analysis/text.h"

namespace eol::analysis {
namespace {

bool PositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

constexpr double kMaxExponent = 0.5;

}  // namespace

bool F0PressureDefinition::IsValid(std::string* why) const {
  const auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!std::isfinite(exponent) || exponent <= 0.0 || exponent > kMaxExponent)
    return fail("exponent must be finite and in (0, 0.5]");
  if (!PositiveFinite(pressure_ref_bar))
    return fail("pressure_ref_bar must be positive and finite");
  return true;
}

std::optional<Estimate> F0AtRefPressure(const std::map<std::string, Estimate>& values,
                                        std::optional<double> clamp_pressure_bar,
                                        const F0PressureDefinition& d) {
  const auto f0 = values.find(std::string(names::kResonanceFHz));
  if (f0 == values.end() || !PositiveFinite(f0->second.value) || !clamp_pressure_bar ||
      !PositiveFinite(*clamp_pressure_bar))
    return std::nullopt;
  const double scale = std::pow(d.pressure_ref_bar / *clamp_pressure_bar, d.exponent);
  return Estimate{f0->second.value * scale, f0->second.sigma * scale};
}

void AddF0AtRefPressure(std::map<std::string, Estimate>& values,
                        std::optional<double> clamp_pressure_bar, const F0PressureDefinition& d) {
  if (const auto e = F0AtRefPressure(values, clamp_pressure_bar, d))
    values[std::string(names::kResonanceFRefPressureHz)] = *e;
}

F0PressureFit TeachF0Pressure(const std::vector<std::pair<double, double>>& f0_and_pressure) {
  F0PressureFit fit;
  fit.units = static_cast<int>(f0_and_pressure.size());
  const double n = static_cast<double>(f0_and_pressure.size());
  double mean_y = 0.0, mean_x = 0.0;
  for (const auto& [f0, p] : f0_and_pressure) {
    if (!PositiveFinite(f0) || !PositiveFinite(p))
      throw std::invalid_argument("f0 pressure fit: f0 and clamp pressure must be positive");
    mean_y += std::log(f0) / n;
    mean_x += std::log(p) / n;
  }
  if (fit.units < 3) {
    fit.note = "not used: fewer than 3 units";
    return fit;
  }
  double sxx = 0.0, syy = 0.0, sxy = 0.0;
  for (const auto& [f0, p] : f0_and_pressure) {
    const double x = std::log(p) - mean_x, y = std::log(f0) - mean_y;
    sxx += x * x;
    syy += y * y;
    sxy += x * y;
  }
  fit.spread_before_pct = 100.0 * std::sqrt(syy / (n - 1.0));
  if (!(sxx > 0.0)) {
    fit.spread_after_pct = fit.spread_before_pct;
    fit.note = "not used: the clamp pressure did not vary among the golden units";
    return fit;
  }
  fit.slope = sxy / sxx;
  const double rss = std::max(0.0, syy - fit.slope * sxy);
  fit.spread_after_pct = 100.0 * std::sqrt(rss / (n - 2.0));
  fit.slope_sigma = std::sqrt(rss / (n - 2.0) / sxx);
  fit.t = fit.slope_sigma > 0.0 ? fit.slope / fit.slope_sigma : 0.0;
  const std::string found =
      "d ln f0 / d ln p = " + Fixed(fit.slope, 4) + " +- " + Fixed(fit.slope_sigma, 4) + " (t " +
      Fixed(fit.t, 1) + ", " + std::to_string(fit.units) + " units); f0 spread " +
      Fixed(fit.spread_before_pct, 3) + " % -> " + Fixed(fit.spread_after_pct, 3) + " %";
  if (fit.t < kF0PressureMinT) {
    fit.note = "not used: " + found + ", t below " + Fixed(kF0PressureMinT, 1);
    return fit;
  }
  if (fit.slope > kMaxExponent) {
    fit.note = "not used: " + found + ", slope beyond the physical 0.5 (k ~ p at most)";
    return fit;
  }
  fit.definition = F0PressureDefinition{fit.slope, std::exp(mean_x)};
  fit.note = "used: " + found + ", p_ref " + Fixed(std::exp(mean_x), 3) + " bar";
  return fit;
}

}  // namespace eol::analysis
