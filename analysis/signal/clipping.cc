#include "analysis/signal/clipping.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "analysis/text.h"

namespace eol::analysis {
namespace {

struct RailCount {
  std::size_t in_runs = 0;  // samples at the level in runs of 2 or more
  std::size_t longest = 0;
};

RailCount CountRail(std::span<const double> x, double level) {
  RailCount c;
  std::size_t run = 0;
  auto close_run = [&] {
    if (run >= 2) c.in_runs += run;
    c.longest = std::max(c.longest, run);
    run = 0;
  };
  for (double v : x) {
    if (v == level)
      ++run;
    else
      close_run();
  }
  close_run();
  return c;
}

// The channel's range and its smallest non-zero step between consecutive finite samples.
struct Shape {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  double min_step = std::numeric_limits<double>::infinity();
};

Shape ShapeOf(std::span<const double> x) {
  Shape s;
  for (std::size_t k = 0; k < x.size(); ++k) {
    if (!std::isfinite(x[k])) continue;
    s.lo = std::min(s.lo, x[k]);
    s.hi = std::max(s.hi, x[k]);
    if (k > 0 && std::isfinite(x[k - 1]) && x[k] != x[k - 1])
      s.min_step = std::min(s.min_step, std::abs(x[k] - x[k - 1]));
  }
  return s;
}

ChannelClipping FindRail(std::span<const double> x) {
  ChannelClipping out;
  const Shape s = ShapeOf(x);
  if (!(s.hi > s.lo) || !std::isfinite(s.min_step) || (s.hi - s.lo) < kMinRailLevels * s.min_step)
    return out;
  const double needed =
      std::max(static_cast<double>(kMinRailRun), kMinRailShare * static_cast<double>(x.size()));
  for (double level : {s.hi, s.lo}) {
    if (level == 0.0 || (level == s.hi) != (level > 0.0)) continue;
    const RailCount c = CountRail(x, level);
    if (c.longest < kMinRailRun && static_cast<double>(c.in_runs) < needed) continue;
    if (out.clipped && c.in_runs <= out.samples) continue;
    out = {true, false, level, std::max(c.in_runs, c.longest), c.longest};
  }
  return out;
}

}  // namespace

ChannelClipping FindClipping(std::span<const double> x, double full_scale) {
  if (full_scale > 0.0) {
    std::size_t n = 0;
    for (double v : x)
      if (std::abs(v) >= kClipFullScaleShare * full_scale) ++n;
    if (n > 0) return {true, true, full_scale, n, 0};
  }
  return FindRail(x);
}

std::string ClippingMessage(const std::string& channel, const std::string& unit,
                            const ChannelClipping& c, std::size_t n) {
  std::ostringstream m = MessageStream();
  m.precision(4);
  m << channel << " clipped at " << c.level << (unit.empty() ? "" : " " + unit) << ": " << c.samples
    << " of " << n << " samples ";
  if (c.at_full_scale)
    m << "at or beyond " << kClipFullScaleShare << " of the converter's full scale";
  else
    m << "repeat the channel's " << (c.level > 0.0 ? "maximum" : "minimum") << " (longest run "
      << c.longest_run << " samples), a converter rail";
  return m.str();
}

}  // namespace eol::analysis
