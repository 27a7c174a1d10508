// The acquisition driver for the simulated bench: plays the excitation into the simulated
// motor that is in the fixture and records voltage and current with white noise on both
// channels, quantised by nothing and clipped at the channels' full scale.
//
// The excitation drives the motor through the bench circuit (analysis/sim/bench_circuit.h:
// amplifier output resistance, motor, current shunt of the calibration); the voltage channel
// reads the motor's terminals. Two motor models ("model" in the config):
//   steady_state  (default, fast) the periodic steady state of every period
//                 (analysis/sim/steady_state.h): no start transient.
//   time_domain   the exact time-domain integration (analysis/sim/time_domain.h) of the
//                 motor from rest, start transient included, with a band-limited input hold.
// With no part in the fixture the voltage channel reads the amplifier and the current is
// zero. While the bench's excitation relay is open both channels read zero (plus noise), and
// the time-domain motor restarts from rest when it closes, so a sequencer that forgets to enable
// the relay, or a watchdog that cuts it, is visible in the data. Pacing: time_scale 1 plays
// in real time, 0 as fast as the machine computes.
//
// Load "reference_resistor" (calibration, analysis/signal/reference_calibration.h): a resistor
// of reference_ohm sits in the fixture instead of the part (its steady state, whatever the
// model). The acquisition's own errors can be injected, so that a calibration has something to
// find: the voltage channel reads injected_gain * u and the current channel reads
// i(t - injected_channel_delay_s) (a periodic fractional delay of the steady-state period;
// the time_domain model takes no delay).
#pragma once

#include <cstdint>
#include <memory>

#include "drivers/daq/daq.h"
#include "drivers/sim/sim_bench.h"

namespace eol::drivers {

enum class SimMotorModel { kSteadyState, kTimeDomain };
const char* ToString(SimMotorModel m);
enum class SimLoad { kFixturePart, kReferenceResistor };
const char* ToString(SimLoad l);

struct SimDaqSettings {
  SimMotorModel model = SimMotorModel::kSteadyState;
  double amplifier_output_ohm = 0.0;  // in series with the motor; the shunt is calibration's
  double time_scale = 0.0;
  double voltage_noise_v = 2.0e-3;  // rms per sample
  double current_noise_a = 1.0e-3;  // rms per sample
  double voltage_full_scale_v = 10.0;
  double current_full_scale_a = 2.0;
  double chunk_s = 0.02;  // relay state, faults and abort are checked per chunk
  // The excitation relay lives in a fixture controller this process cannot see (a fixture
  // over Modbus or CAN to `eol fixture-sim` in another process): the simulated motor is
  // taken as connected while acquiring. Config "relay": "bench" (default) or "external".
  bool relay_external = false;
  std::uint64_t seed = 7;
  Calibration calibration;
  SimLoad load = SimLoad::kFixturePart;
  double reference_ohm = 1.0;             // the resistor of SimLoad::kReferenceResistor
  double injected_gain = 1.0;             // voltage channel reads injected_gain * u
  double injected_channel_delay_s = 0.0;  // current channel reads i(t - delay)
};

class SimDaq final : public Daq {
 public:
  SimDaq(std::shared_ptr<SimBench> bench, SimDaqSettings settings);

 protected:
  void DoConnect() override {}
  void DoDisconnect() override {}
  analysis::Recording DoAcquire(const AcquisitionRequest& request,
                                const std::atomic<bool>& abort) override;
  Calibration DoCalibration() const override { return settings_.calibration; }

 private:
  std::shared_ptr<SimBench> bench_;
  SimDaqSettings settings_;
  std::uint64_t acquisitions_ = 0;
};

}  // namespace eol::drivers
