// Data checks shared by the FRF estimators (periodic_frf.h, transient_frf.h, welch.h): the reasons
// a pair of sample streams cannot be analysed at all, before any spectrum is computed.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "analysis/signal/recording.h"

namespace eol::analysis {

// Why a pair cannot be analysed; empty() when it may be.
struct ChannelProblem {
  std::string message;
  bool clipped = false;  // a channel reached its range (reason code "clipped", measurement.h)
  bool empty() const { return message.empty(); }
};

// The reason, naming the channel and sample:
//   - the channels have different lengths;
//   - a sample is not finite ("voltage sample 12 is not finite (NaN or inf)");
//   - a channel clipped (clipping.h: at its full scale, or repeated at a rail), with the level
//     and the counts: "current clipped at 2 A: 812 of 40000 samples at or beyond 0.999 of the
//     converter's full scale; lower the excitation level or raise the range".
ChannelProblem CheckChannels(const ChannelPair& pair);

// Empty when a periodic pair and its excited lines (bins of one period) may be analysed;
// otherwise the reason: no period or no lines, a sample rate that is not positive, a line at
// DC or at/above Nyquist, or any reason of CheckChannels.
ChannelProblem CheckPeriodicPair(const ChannelPair& pair, const std::vector<std::size_t>& lines);

// The "no signal" refusal (more than a tenth of the lines without input above the noise:
// open circuit, relay off, amplifier dead), naming the input channel and the worst line SNR.
// Empty when weak_lines * 10 <= lines.
std::string NoSignalMessage(const ChannelPair& pair, std::size_t weak_lines, std::size_t lines,
                            double worst_snr);

}  // namespace eol::analysis
