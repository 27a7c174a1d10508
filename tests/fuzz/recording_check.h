// The contract both recording readers share (drivers/io/recording_files.h).
#pragma once

#include <cmath>
#include <string>

#include "analysis/signal/recording.h"
#include "tests/fuzz/fuzz_support.h"

namespace eol::fuzz {

inline void CheckRecording(const analysis::Recording& r, const std::string& reader) {
  if (r.voltage_v.size() != r.current_a.size())
    Finding(reader + ": voltage and current differ in length");
  if (r.voltage_v.empty()) Finding(reader + ": no samples");
  if (!(std::isfinite(r.sample_rate_hz) && r.sample_rate_hz > 0.0))
    Finding(reader + ": sample rate " + std::to_string(r.sample_rate_hz) +
            " is not finite and positive");
  if (!AllFinite(r.voltage_v) || !AllFinite(r.current_a))
    Finding(reader + ": a sample is not finite");
}

}  // namespace eol::fuzz
