#include "analysis/sim/bench_circuit.h"

namespace eol::analysis {

ChannelSamples SteadyStatePeriod(const ImpedanceFn& motor_z, const BenchCircuit& circuit,
                                 const std::vector<double>& amplifier_period_v,
                                 double sample_rate_hz) {
  const double series = circuit.SeriesOhm();
  ChannelSamples out;
  out.current_a = SteadyStateCurrent([&](double f) { return motor_z(f) + series; },
                                     amplifier_period_v, sample_rate_hz);
  out.voltage_v.resize(amplifier_period_v.size());
  for (std::size_t t = 0; t < amplifier_period_v.size(); ++t)
    out.voltage_v[t] = amplifier_period_v[t] - series * out.current_a[t];
  return out;
}

}  // namespace eol::analysis
