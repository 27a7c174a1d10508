// Clipping of a recorded channel: the converter's range reached, found before any spectrum
// or fit (channel_checks.h), so a clipped recording is refused as "current clipped at 2 A"
// instead of being fitted into misleading values (a winding temperature of -57 degC, Q 1.3).
//
// Two rules, the first that applies wins:
//   1. full scale known (> 0): any sample at or beyond kClipFullScaleShare of it is clipped
//      ("at" the full scale);
//   2. a rail (full scale unknown, e.g. a recording CSV that does not state it, or known but
//      the converter saturated below it): the channel's largest (or smallest) value is repeated
//      by consecutive samples, as an ADC's code does at its limit. Clipped when one run at the
//      extreme lasts kMinRailRun samples or more, or when the samples in runs of 2 or more at
//      the extreme are at least kMinRailShare of the channel (and kMinRailRun). A smooth signal
//      passes its extreme in one sample; a constant channel, an extreme of the other sign
//      than the side (a channel entirely above 0 has no bottom rail) and a channel too coarse
//      to tell a rail from its quantisation (its swing less than kMinRailLevels of its smallest
//      step between samples: noise of a few codes, an open circuit) are not rails; an open
//      circuit is refused as "no signal" instead.
#pragma once

#include <cstddef>
#include <span>
#include <string>

namespace eol::analysis {

inline constexpr double kClipFullScaleShare = 0.999;
inline constexpr std::size_t kMinRailRun = 8;
inline constexpr double kMinRailShare = 0.001;  // 0.1 % of the samples
inline constexpr double kMinRailLevels = 64.0;

struct ChannelClipping {
  bool clipped = false;
  bool at_full_scale = false;   // rule 1; else a rail (rule 2)
  double level = 0.0;           // the full scale, or the rail's (signed) value
  std::size_t samples = 0;      // samples at the full scale or at the rail
  std::size_t longest_run = 0;  // rule 2: the longest run of consecutive samples at the rail
};

// Non-finite samples are skipped (CheckChannels refuses them first).
ChannelClipping FindClipping(std::span<const double> x, double full_scale);

// "current clipped at 2 A: 812 of 40000 samples at or beyond 0.999 of the converter's full
// scale" or "current clipped at 1.532 A: 812 of 40000 samples repeat the channel's maximum
// (longest run 37 samples), a converter rail". `unit` may be empty.
std::string ClippingMessage(const std::string& channel, const std::string& unit,
                            const ChannelClipping& c, std::size_t n);

}  // namespace eol::analysis
