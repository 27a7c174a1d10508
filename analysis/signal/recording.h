// Sample streams recorded by an acquisition device, in physical units.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "analysis/frf.h"

namespace eol::analysis {

// Voltage across the excited phase pair and current through it, sampled synchronously.
// For a periodic excitation the stream holds whole periods of period_samples each.
struct Recording {
  double sample_rate_hz = 0.0;
  std::size_t period_samples = 0;  // 0 when the excitation was not periodic
  std::vector<double> voltage_v;
  std::vector<double> current_a;
  // Full-scale of each channel (the ADC range after gains); samples at or beyond 0.999 of it
  // count as clipped. 0 means unknown: clipping is then found from samples repeated at a rail
  // (analysis/signal/clipping.h).
  double voltage_full_scale_v = 0.0;
  double current_full_scale_a = 0.0;

  std::size_t periods() const {
    return period_samples == 0 ? 0 : voltage_v.size() / period_samples;
  }
};

// Any two synchronously sampled channels seen as a transfer H = (j w)^output_jw_power Y / X:
// input x (the excitation side, e.g. current), output y (e.g. voltage, or a motor angle with
// output_jw_power = 1 to get angular velocity per current). The spans view the caller's
// samples, which must outlive the pair. Names appear in every message ("current sample 12 is
// not finite"). Full scales as in Recording (0: unknown; clipping.h then looks for a rail).
struct ChannelPair {
  double sample_rate_hz = 0.0;
  std::size_t period_samples = 0;  // 0 when not periodic
  std::span<const double> x;
  std::span<const double> y;
  std::string x_name = "input";
  std::string y_name = "output";
  std::string x_unit;  // in messages ("current clipped at 2 A"); may be empty
  std::string y_unit;
  double x_full_scale = 0.0;
  double y_full_scale = 0.0;
  Quantity quantity = Quantity::kImpedanceOhm;  // what H is
  int output_jw_power = 0;                      // 0: H = Y / X; 1: H = j w Y / X

  // The impedance view of a recording: x = current, y = voltage, H = Z = U / I.
  static ChannelPair Impedance(const Recording& recording);
};

inline ChannelPair ChannelPair::Impedance(const Recording& r) {
  ChannelPair p;
  p.sample_rate_hz = r.sample_rate_hz;
  p.period_samples = r.period_samples;
  p.x = r.current_a;
  p.y = r.voltage_v;
  p.x_name = "current";
  p.y_name = "voltage";
  p.x_unit = "A";
  p.y_unit = "V";
  p.x_full_scale = r.current_full_scale_a;
  p.y_full_scale = r.voltage_full_scale_v;
  p.quantity = Quantity::kImpedanceOhm;
  return p;
}

}  // namespace eol::analysis
