// Data checks shared by the FRF estimators (periodic_frf.h, welch.h): the reasons a pair of
// sample streams cannot be analysed at all, before any spectrum is computed.
#pragma once

#include <string>

#include "analysis/signal/recording.h"

namespace eol::analysis {

// Empty when the pair may be analysed; otherwise the reason, naming the channel and sample:
//   - the channels have different lengths;
//   - a sample is not finite ("voltage sample 12 is not finite (NaN or inf)");
//   - samples at or beyond 0.999 of a channel's full scale (clipping), with their counts.
std::string CheckChannels(const ChannelPair& pair);

}  // namespace eol::analysis
