#include "drivers/daq/daq.h"

#include <exception>

namespace eol::drivers {

Daq::Daq(std::string name) : name_(std::move(name)) {}
Daq::~Daq() = default;

Lifecycle Daq::lifecycle() const {
  std::lock_guard<std::mutex> lock(mu_);
  return state_;
}

Status Daq::Connect() {
  std::lock_guard<std::mutex> lock(mu_);
  if (state_ == Lifecycle::kInactive) return Status::Ok();
  try {
    DoConnect();
  } catch (const std::exception& e) {
    state_ = Lifecycle::kError;
    return Status::Error("daq '" + name_ + "': connect: " + e.what());
  }
  state_ = Lifecycle::kInactive;
  return Status::Ok();
}

void Daq::Disconnect() {
  std::lock_guard<std::mutex> lock(mu_);
  if (state_ == Lifecycle::kUnconfigured || state_ == Lifecycle::kFinalized) return;
  try {
    DoDisconnect();
  } catch (const std::exception&) {
    // Nothing more to do: the device is going away either way.
  }
  state_ = Lifecycle::kFinalized;
}

StatusOr<analysis::Recording> Daq::Acquire(const AcquisitionRequest& request,
                                           const std::atomic<bool>& abort) {
  std::lock_guard<std::mutex> lock(mu_);
  if (state_ != Lifecycle::kInactive)
    return Status::Error("daq '" + name_ + "': acquire: not connected (state " + ToString(state_) +
                         ")");
  if (request.sample_rate_hz <= 0.0 || request.excitation_v.empty())
    return Status::Error("daq '" + name_ + "': acquire: empty excitation or no sample rate");
  try {
    return DoAcquire(request, abort);
  } catch (const AcquisitionAborted& e) {
    return Status::Error("daq '" + name_ + "': " + e.what());
  } catch (const std::exception& e) {
    state_ = Lifecycle::kError;
    return Status::Error("daq '" + name_ + "': acquire: " + e.what());
  }
}

Calibration Daq::calibration() const {
  std::lock_guard<std::mutex> lock(mu_);
  return DoCalibration();
}

}  // namespace eol::drivers
