#include "analysis/signal/channel_checks.h"

#include <cmath>
#include <sstream>
#include <tuple>

#include "analysis/signal/clipping.h"

namespace eol::analysis {
namespace {

// Index of the first non-finite sample, or -1.
long FirstNonFinite(std::span<const double> x) {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i])) return static_cast<long>(i);
  return -1;
}

}  // namespace

ChannelProblem CheckChannels(const ChannelPair& p) {
  if (p.x.size() != p.y.size())
    return {p.y_name + " and " + p.x_name + " have different lengths (" +
            std::to_string(p.y.size()) + " vs " + std::to_string(p.x.size()) + " samples)"};
  for (auto [name, s] : {std::pair{&p.y_name, p.y}, {&p.x_name, p.x}}) {
    const long bad = FirstNonFinite(s);
    if (bad >= 0) return {*name + " sample " + std::to_string(bad) + " is not finite (NaN or inf)"};
  }
  std::string clipped;
  for (auto [name, unit, s, fs] : {std::tuple{&p.y_name, &p.y_unit, p.y, p.y_full_scale},
                                   std::tuple{&p.x_name, &p.x_unit, p.x, p.x_full_scale}}) {
    const ChannelClipping c = FindClipping(s, fs);
    if (c.clipped)
      clipped += (clipped.empty() ? "" : "; ") + ClippingMessage(*name, *unit, c, s.size());
  }
  if (!clipped.empty()) return {clipped + "; lower the excitation level or raise the range", true};
  return {};
}

ChannelProblem CheckPeriodicPair(const ChannelPair& pair, const std::vector<std::size_t>& lines) {
  const std::size_t n = pair.period_samples;
  if (n < 2 || lines.empty()) return {"recording is not periodic or no lines are excited"};
  if (!(pair.sample_rate_hz > 0.0)) return {"sample rate must be positive"};
  if (lines.front() == 0 || lines.back() >= n / 2)
    return {"excited line " + std::to_string(lines.front() == 0 ? 0 : lines.back()) +
            " is DC or above Nyquist"};
  return CheckChannels(pair);
}

std::string NoSignalMessage(const ChannelPair& pair, std::size_t weak_lines, std::size_t lines,
                            double worst_snr) {
  if (weak_lines * 10 <= lines) return "";
  std::ostringstream m;
  m << "no signal: " << weak_lines << " of " << lines << " excited lines have no " << pair.x_name
    << " above the noise (worst line SNR " << worst_snr
    << "); check the excitation relay, amplifier and wiring";
  return m.str();
}

}  // namespace eol::analysis
