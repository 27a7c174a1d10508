#include "analysis/qc/curve_mask.h"

#include <cmath>

namespace eol::analysis {
namespace {

// Linear interpolation of one bound between the points around f; nullopt where either
// neighbour leaves that side open.
std::optional<double> BoundAt(const std::vector<MaskPoint>& pts, double f,
                              std::optional<double> MaskPoint::*side) {
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const MaskPoint& a = pts[i];
    const MaskPoint& b = pts[i + 1];
    if (f < a.f_hz || f > b.f_hz) continue;
    if (!(a.*side) || !(b.*side)) return std::nullopt;
    const double t = (f - a.f_hz) / (b.f_hz - a.f_hz);
    return *(a.*side) + t * (*(b.*side) - *(a.*side));
  }
  return std::nullopt;
}

}  // namespace

MeasurementSpec CurveMask::Spec() const {
  MeasurementSpec s;
  s.name = MeasurementName();
  s.unit = "lines";
  s.doc = std::string("lines of ") + (quantity == MaskQuantity::kReOhm ? "Re Z" : "|Z|") +
          " outside the limit mask '" + name + "'";
  s.limit.hi = max_lines_outside;
  return s;
}

bool CurveMask::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (points.size() < 2) return fail("a mask needs at least two points");
  for (std::size_t i = 0; i < points.size(); ++i) {
    const MaskPoint& p = points[i];
    if (!(p.f_hz > 0)) return fail("point " + std::to_string(i) + ": f_hz must be positive");
    if (i > 0 && !(p.f_hz > points[i - 1].f_hz))
      return fail("point " + std::to_string(i) + ": f_hz must increase");
    if (!p.lo && !p.hi) return fail("point " + std::to_string(i) + ": needs lo, hi or both");
    if (p.lo && p.hi && !(*p.hi > *p.lo))
      return fail("point " + std::to_string(i) + ": hi must be greater than lo");
  }
  if (max_lines_outside < 0) return fail("max_lines_outside must not be negative");
  if (!(guard_sigma >= 0)) return fail("guard_sigma must not be negative");
  return true;
}

MaskCheck CheckMask(const Frf& z, const CurveMask& mask) {
  MaskCheck c;
  for (std::size_t k = 0; k < z.size(); ++k) {
    const double f = z.freq_hz[k];
    if (f < mask.points.front().f_hz || f > mask.points.back().f_hz) continue;
    ++c.lines_checked;
    const double v =
        mask.quantity == MaskQuantity::kReOhm ? z.value[k].real() : std::abs(z.value[k]);
    const double guard = z.has_sigma() ? mask.guard_sigma * z.sigma[k] : 0.0;
    double excess = 0.0;
    if (const auto hi = BoundAt(mask.points, f, &MaskPoint::hi); hi && v > *hi + guard)
      excess = v - *hi;
    if (const auto lo = BoundAt(mask.points, f, &MaskPoint::lo); lo && v < *lo - guard)
      excess = *lo - v;
    if (excess > 0.0) {
      ++c.lines_outside;
      if (excess > c.worst_excess) {
        c.worst_excess = excess;
        c.worst_f_hz = f;
      }
    }
  }
  return c;
}

}  // namespace eol::analysis
