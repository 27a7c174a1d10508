#include "analysis/qc/bond_index.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "analysis/qc/measurement_names.h"

namespace eol::analysis {
namespace {

bool PositiveFinite(double v) { return std::isfinite(v) && v > 0.0; }

}  // namespace

bool BondIndexDefinition::IsValid(std::string* why) const {
  const auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (f0_name != names::kResonanceFHz && f0_name != names::kResonanceFRefPressureHz)
    return fail("f0 must be resonance_f_hz or resonance_f_ref_pressure_hz");
  if (!std::isfinite(f0_exponent) || f0_exponent < 0.0 || f0_exponent > 1000.0)
    return fail("f0_exponent must be finite and in [0, 1000]");
  if (!PositiveFinite(f0_ref_hz)) return fail("f0_ref_hz must be positive and finite");
  if (!PositiveFinite(residue_ref_ohm_per_s))
    return fail("residue_ref_ohm_per_s must be positive and finite");
  if (!PositiveFinite(residue_to_f0) || residue_to_f0 > kMaxResidueToF0)
    return fail("residue_to_f0 must be positive, finite and at most 1000");
  return true;
}

std::optional<Estimate> BondIndex(const std::map<std::string, Estimate>& values,
                                  const BondIndexDefinition& d) {
  const auto f0 = values.find(d.f0_name);
  const auto a = values.find(std::string(names::kMotionalResidueOhmPerS));
  if (f0 == values.end() || a == values.end() || !PositiveFinite(f0->second.value) ||
      !PositiveFinite(a->second.value))
    return std::nullopt;
  const double m = d.f0_exponent;
  const double value = 100.0 * (std::log(a->second.value / d.residue_ref_ohm_per_s) -
                                m * std::log(f0->second.value / d.f0_ref_hz));
  const double rel_a = a->second.sigma / a->second.value;
  const double rel_f0 = f0->second.sigma / f0->second.value;
  return Estimate{value, 100.0 * std::sqrt(rel_a * rel_a + m * m * rel_f0 * rel_f0)};
}

void AddBondIndex(std::map<std::string, Estimate>& values, const BondIndexDefinition& d) {
  if (const auto index = BondIndex(values, d)) values[std::string(names::kBondIndexPct)] = *index;
}

BondIndexDefinition TeachBondIndex(const std::vector<std::pair<double, double>>& f0_and_residue,
                                   double residue_to_f0) {
  if (!PositiveFinite(residue_to_f0) || residue_to_f0 > kMaxResidueToF0)
    throw std::invalid_argument("bond index: residue_to_f0 must be positive and at most 1000");
  const double n = static_cast<double>(f0_and_residue.size());
  double mean_f = 0.0, mean_a = 0.0;
  for (const auto& [f0, a] : f0_and_residue) {
    if (!PositiveFinite(f0) || !PositiveFinite(a))
      throw std::invalid_argument("bond index: f0 and residue must be positive and finite");
    mean_f += std::log(f0) / n;
    mean_a += std::log(a) / n;
  }
  BondIndexDefinition d;
  d.residue_to_f0 = residue_to_f0;
  d.f0_ref_hz = std::exp(mean_f);
  d.residue_ref_ohm_per_s = std::exp(mean_a);
  if (f0_and_residue.size() < 3) return d;
  double sff = 0.0, saa = 0.0, sfa = 0.0;
  for (const auto& [f0, a] : f0_and_residue) {
    const double x = std::log(f0) - mean_f, y = std::log(a) - mean_a;
    sff += x * x;
    saa += y * y;
    sfa += x * y;
  }
  // w = S^-1 d with d = (-1, residue_to_f0); S^-1 = [saa -sfa; -sfa sff] / det (det > 0 for
  // units that are not collinear; the common factor 1/det and 1/(n-1) cancel in m).
  const double w_f = -saa - sfa * residue_to_f0;
  const double w_a = sfa + sff * residue_to_f0;
  const double det = sff * saa - sfa * sfa;
  if (!(det > 0.0) || !(w_a > 0.0)) return d;
  d.f0_exponent = std::max(0.0, -w_f / w_a);
  return d;
}

}  // namespace eol::analysis
