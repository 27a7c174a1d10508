// The acquisition device: plays an excitation (volts at the amplifier input) and records
// phase-pair voltage and current sample-synchronously, in physical units, with the
// calibration that converted them. Backends: sim (the motor simulator), alsa, replay.
#pragma once

#include <atomic>
#include <cstddef>
#include <mutex>
#include <string>
#include <vector>

#include "analysis/signal/recording.h"
#include "drivers/status.h"

namespace eol::drivers {

// How raw channel readings became volts and amperes; stored with every test.
struct Calibration {
  double shunt_ohm = 0.1;          // current channel: volts across the shunt / shunt_ohm
  double divider_ratio = 1.0;      // voltage channel: phase volts per channel volt
  double channel_delay_s = 0.0;    // current channel lags voltage channel by this much
  std::string method = "nominal";  // "nominal", or how it was measured (reference resistor)
  // Set by a measured calibration (method "reference_resistor", calibration_file.h): when it
  // was measured (ISO 8601 UTC) and the reference resistor it was measured with.
  std::string date;
  double reference_ohm = 0.0;
};

struct AcquisitionRequest {
  double sample_rate_hz = 0.0;
  std::size_t period_samples = 0;    // 0 for a non-periodic excitation
  std::vector<double> excitation_v;  // the whole stream to play
};

class Daq {
 public:
  virtual ~Daq();
  Daq(const Daq&) = delete;
  Daq& operator=(const Daq&) = delete;
  Daq(Daq&&) = delete;
  Daq& operator=(Daq&&) = delete;

  const std::string& name() const { return name_; }
  Lifecycle lifecycle() const;

  Status Connect();
  void Disconnect();
  // Blocks until the whole excitation is played and recorded. When `abort` becomes true the
  // output is silenced first and an error is returned ("aborted"). Thread-safe against a
  // concurrent abort only (one acquisition at a time).
  StatusOr<analysis::Recording> Acquire(const AcquisitionRequest& request,
                                        const std::atomic<bool>& abort);
  Calibration calibration() const;

 protected:
  explicit Daq(std::string name);
  virtual void DoConnect() = 0;
  virtual void DoDisconnect() = 0;
  // Throws DeviceError on failure, AcquisitionAborted when `abort` was seen.
  virtual analysis::Recording DoAcquire(const AcquisitionRequest& request,
                                        const std::atomic<bool>& abort) = 0;
  virtual Calibration DoCalibration() const = 0;

 private:
  const std::string name_;
  mutable std::mutex mu_;
  Lifecycle state_ = Lifecycle::kUnconfigured;
};

class AcquisitionAborted : public DeviceError {
 public:
  AcquisitionAborted() : DeviceError("aborted: excitation stopped") {}
};

}  // namespace eol::drivers
