// The acquisition driver for the simulated bench: plays the excitation into the simulated
// motor that is in the fixture and records voltage and current with white noise on both
// channels, quantised by nothing and clipped at the channels' full scale.
//
// The recorded current is the motor's periodic steady state (analysis/sim/steady_state.h)
// while the bench's excitation relay is closed and zero (plus noise) while it is open, so a
// sequencer that forgets to enable the relay, or a watchdog that cuts it, is visible in the
// data. Pacing: time_scale 1 plays in real time, 0 as fast as the machine computes.
#pragma once

#include <cstdint>
#include <memory>

#include "drivers/daq/daq.h"
#include "drivers/sim/sim_bench.h"

namespace eol::drivers {

struct SimDaqSettings {
  double time_scale = 0.0;
  double voltage_noise_v = 2.0e-3;  // rms per sample
  double current_noise_a = 1.0e-3;  // rms per sample
  double voltage_full_scale_v = 10.0;
  double current_full_scale_a = 2.0;
  double chunk_s = 0.02;            // relay state, faults and abort are checked per chunk
  std::uint64_t seed = 7;
  Calibration calibration;
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
