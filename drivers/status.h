// Results of hardware, I/O and user-input operations: a code-free status with a message
// that names the device, signal or address, the attempt and the timeout (drivers/README.md,
// Contracts). Programmer errors are not Status: they throw std::logic_error or abort.
#pragma once

#include <optional>
#include <stdexcept>
#include <string>
#include <utility>

namespace eol::drivers {

class Status {
 public:
  static Status Ok() { return Status(); }
  static Status Error(std::string message) { return Status(std::move(message)); }
  bool ok() const { return !message_.has_value(); }
  explicit operator bool() const { return ok(); }
  const std::string& message() const {
    static const std::string kOk = "ok";
    return message_ ? *message_ : kOk;
  }

 private:
  Status() = default;
  explicit Status(std::string m) : message_(std::move(m)) {}
  std::optional<std::string> message_;
};

template <typename T>
class StatusOr {
 public:
  StatusOr(T value) : value_(std::move(value)), status_(Status::Ok()) {}  // NOLINT: implicit
  StatusOr(Status error) : status_(std::move(error)) {                    // NOLINT: implicit
    if (status_.ok()) throw std::logic_error("StatusOr constructed from an ok Status");
  }
  bool ok() const { return status_.ok(); }
  const Status& status() const { return status_; }
  const T& value() const {
    if (!ok()) throw std::logic_error("StatusOr::value() on error: " + status_.message());
    return *value_;
  }
  T& value() {
    if (!ok()) throw std::logic_error("StatusOr::value() on error: " + status_.message());
    return *value_;
  }

 private:
  std::optional<T> value_;
  Status status_;
};

// Thrown by a driver's protected hooks; the public wrapper turns it into a Status that
// names the device.
class DeviceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Lifecycle every hardware object goes through (ros2_control style):
//   kUnconfigured --Connect--> kInactive (connected, read-only) --Activate--> kActive
//   (outputs may be driven) --Deactivate--> kInactive --Disconnect--> kFinalized;
//   any hook failure --> kError (Connect again to recover).
enum class Lifecycle { kUnconfigured, kInactive, kActive, kFinalized, kError };
const char* ToString(Lifecycle s);

}  // namespace eol::drivers
