// Sample streams recorded by an acquisition device, in physical units.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace eol::analysis {

// Voltage across the excited phase pair and current through it, sampled synchronously.
// For a periodic excitation the stream holds whole periods of period_samples each.
struct Recording {
  double sample_rate_hz = 0.0;
  std::size_t period_samples = 0;  // 0 when the excitation was not periodic
  std::vector<double> voltage_v;
  std::vector<double> current_a;
  // Full-scale of each channel (the ADC range after gains); samples at or beyond 0.999 of it
  // count as clipped. 0 means unknown (no clipping check).
  double voltage_full_scale_v = 0.0;
  double current_full_scale_a = 0.0;

  std::size_t periods() const {
    return period_samples == 0 ? 0 : voltage_v.size() / period_samples;
  }
};

}  // namespace eol::analysis
