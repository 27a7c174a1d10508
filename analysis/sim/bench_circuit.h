// The excitation circuit of the bench, shared by the steady-state and time-domain simulators:
//
//   amplifier (voltage source u_amp, output resistance R_out) -> motor phase pair -> current
//   shunt R_sh -> back to the amplifier
//
// The voltage channel reads the motor's terminals, the current channel the shunt (volts /
// R_sh), so the recorded pair is u_motor = u_amp - (R_out + R_sh) i and i, and U / I is the
// motor's Z whatever R_out and R_sh are; they only lower the current.
#pragma once

#include <vector>

#include "analysis/sim/steady_state.h"

namespace eol::analysis {

struct BenchCircuit {
  double amplifier_output_ohm = 0.0;  // R_out
  double shunt_ohm = 0.0;             // R_sh

  double SeriesOhm() const { return amplifier_output_ohm + shunt_ohm; }
};

struct ChannelSamples {
  std::vector<double> voltage_v;  // u_motor
  std::vector<double> current_a;  // i
};

// The periodic steady state of one period of u_amp (steady_state.h):
//   i = SteadyStateCurrent(Z + R_out + R_sh, u_amp),  u_motor = u_amp - (R_out + R_sh) i.
ChannelSamples SteadyStatePeriod(const ImpedanceFn& motor_z, const BenchCircuit& circuit,
                                 const std::vector<double>& amplifier_period_v,
                                 double sample_rate_hz);

}  // namespace eol::analysis
