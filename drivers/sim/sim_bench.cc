#include "drivers/sim/sim_bench.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

namespace eol::drivers {

const char* ToString(SimFault f) {
  switch (f) {
    case SimFault::kStopsAnswering:
      return "stops_answering";
    case SimFault::kClampDrops:
      return "clamp_drops";
    case SimFault::kPressureLow:
      return "pressure_low";
    case SimFault::kDoorOpens:
      return "door_opens";
    case SimFault::kEstop:
      return "estop";
    case SimFault::kHeartbeatFreezes:
      return "heartbeat_freezes";
    case SimFault::kDaqFails:
      return "daq_fails";
    case SimFault::kClampSticks:
      return "clamp_sticks";
  }
  return "unknown";
}

std::optional<SimFault> ParseSimFault(const std::string& s) {
  for (SimFault f : kSimFaults)
    if (s == ToString(f)) return f;
  return std::nullopt;
}

SimBench::SimBench(SimBenchSettings settings, SimClock now)
    : settings_(std::move(settings)), now_(std::move(now)), born_(now_()) {
  latch_since_.fill(born_);
}

void SimBench::LoadPart(const std::string& serial) {
  analysis::SimUnit unit;
  const SimMaster* master = nullptr;
  for (const SimMaster& m : settings_.masters)
    if (m.serial == serial) master = &m;
  if (master) {
    analysis::MotorPopulation nominal = settings_.population;
    for (double* spread :
         {&nominal.spread_inertia, &nominal.spread_k_rotor, &nominal.spread_k_fixture,
          &nominal.spread_q, &nominal.spread_r, &nominal.spread_l, &nominal.spread_transmission})
      *spread = 0.0;
    unit = analysis::DrawUnit(nominal, serial, master->defective);
  } else {
    unit = analysis::DrawUnit(settings_.population, serial);
  }
  double pressure = settings_.clamp_pressure_bar;
  if (!master && settings_.clamp_pressure_spread_bar > 0.0) {
    std::seed_seq seed(serial.begin(), serial.end());  // the same part, the same pressure
    std::mt19937_64 rng(seed);
    const double p0 = settings_.clamp_pressure_bar;
    pressure = std::clamp(
        p0 + settings_.clamp_pressure_spread_bar * std::normal_distribution<double>()(rng),
        0.8 * p0, 1.2 * p0);
    unit.rotor.k_fixture_nm_per_rad *= std::pow(pressure / p0, settings_.fixture_pressure_exponent);
  }
  std::lock_guard<std::mutex> lock(mu_);
  part_pressure_bar_ = pressure;
  const double wear = settings_.fixture_wear_per_test * static_cast<double>(parts_loaded_++);
  unit.rotor.k_fixture_nm_per_rad *= std::max(0.05, 1.0 - wear);
  part_ = unit;
}

void SimBench::LoadUnit(const analysis::SimUnit& unit) {
  std::lock_guard<std::mutex> lock(mu_);
  part_ = unit;
  part_pressure_bar_ = settings_.clamp_pressure_bar;
}

void SimBench::RemovePart() {
  std::lock_guard<std::mutex> lock(mu_);
  part_.reset();
}

std::optional<analysis::SimUnit> SimBench::part() const {
  std::lock_guard<std::mutex> lock(mu_);
  return part_;
}

std::optional<SimBench::Clock::time_point> SimBench::FaultVisibleAtLocked() const {
  if (!fault_) return std::nullopt;
  if (!fault_->on_excitation) return fault_->armed_at + fault_->delay;
  if (!fault_->triggered_at) return std::nullopt;
  return *fault_->triggered_at + fault_->delay;
}

bool SimBench::FaultActiveLocked(SimFault fault, Clock::time_point now) const {
  if (!fault_ || fault_->fault != fault) return false;
  const auto visible = FaultVisibleAtLocked();
  if (!visible || now < *visible) return false;
  return !fault_->duration || now < *visible + *fault_->duration;
}

bool SimBench::FaultSeenLocked(SimFault fault, Clock::time_point since,
                               Clock::time_point now) const {
  if (!fault_ || fault_->fault != fault) return false;
  const auto visible = FaultVisibleAtLocked();
  if (!visible || now < *visible) return false;
  return !fault_->duration || *visible + *fault_->duration > since;
}

void SimBench::CheckAnsweringLocked(Clock::time_point now) const {
  if (FaultActiveLocked(SimFault::kStopsAnswering, now))
    throw DeviceError("no answer from the fixture controller (simulated: stops_answering)");
}

bool SimBench::AliveFreshLocked(Clock::time_point now) const {
  if (settings_.alive_timeout_ms <= 0.0) return true;
  return alive_changed_at_ && now - *alive_changed_at_ <= std::chrono::duration<double, std::milli>(
                                                              settings_.alive_timeout_ms);
}

void SimBench::ExpireAliveLocked(Clock::time_point now) const {
  if (!excitation_ || AliveFreshLocked(now)) return;
  excitation_ = false;
  // The controller opened the relay the moment the alive value went stale.
  excitation_off_at_ = *alive_changed_at_ +
                       std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double, std::milli>(settings_.alive_timeout_ms));
}

// The inputs at `now`, each latched interlock reporting a drop seen since its latch_since_.
FixtureInputs SimBench::InputsLocked(Clock::time_point now) const {
  const auto since = [this](SimLatch l) { return latch_since_[static_cast<std::size_t>(l)]; };
  FixtureInputs in;
  const double since_cmd = clamp_cmd_at_
                               ? std::chrono::duration<double>(now - *clamp_cmd_at_).count()
                               : std::numeric_limits<double>::infinity();
  const bool dropped = FaultSeenLocked(SimFault::kClampDrops, since(SimLatch::kClamped), now);
  if (clamp_cmd_) {
    in.clamped = part_.has_value() && since_cmd >= settings_.clamp_close_s && !dropped;
    in.released = false;
    // Pressure ramps up over the closing time, with a small ripple.
    const double ramp = std::clamp(since_cmd / settings_.clamp_close_s, 0.0, 1.0);
    in.clamp_pressure_bar = part_ ? part_pressure_bar_ * ramp : 0.0;
    in.clamp_pressure_bar += 0.02 * std::sin(since_cmd * 37.0) * ramp;
  } else {
    in.clamped = false;
    in.released =
        since_cmd >= settings_.clamp_open_s && !FaultActiveLocked(SimFault::kClampSticks, now);
    in.clamp_pressure_bar = 0.0;
  }
  const auto pressure_since = since(SimLatch::kClampPressure);
  if (FaultSeenLocked(SimFault::kClampDrops, pressure_since, now)) in.clamp_pressure_bar = 0.0;
  if (FaultSeenLocked(SimFault::kPressureLow, pressure_since, now)) in.clamp_pressure_bar = 1.0;
  in.part_present = part_.has_value();
  in.door_closed = !FaultSeenLocked(SimFault::kDoorOpens, since(SimLatch::kDoorClosed), now);
  in.estop_ok = !FaultSeenLocked(SimFault::kEstop, since(SimLatch::kEstopOk), now);
  const double alive_s = std::chrono::duration<double>(now - born_).count();
  const auto beat = static_cast<std::uint32_t>(alive_s / settings_.heartbeat_period_s);
  if (FaultActiveLocked(SimFault::kHeartbeatFreezes, now)) {
    in.heartbeat = frozen_heartbeat_;
  } else {
    in.heartbeat = beat;
    frozen_heartbeat_ = beat;
  }
  return in;
}

FixtureInputs SimBench::ReadInputs() {
  std::lock_guard<std::mutex> lock(mu_);
  const auto now = now_();
  CheckAnsweringLocked(now);
  ExpireAliveLocked(now);
  const FixtureInputs in = InputsLocked(now);
  latch_since_.fill(now);
  return in;
}

FixtureInputs SimBench::PeekInputs() const {
  std::lock_guard<std::mutex> lock(mu_);
  const auto now = now_();
  CheckAnsweringLocked(now);
  ExpireAliveLocked(now);
  return InputsLocked(now);
}

void SimBench::ClearLatch(SimLatch latch, Clock::time_point as_of) {
  std::lock_guard<std::mutex> lock(mu_);
  auto& since = latch_since_[static_cast<std::size_t>(latch)];
  since = std::max(since, as_of);
}

void SimBench::WriteAlive(std::uint16_t value) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto now = now_();
  CheckAnsweringLocked(now);
  ExpireAliveLocked(now);  // a stale relay opened before this change, not kept by it
  if (alive_ && *alive_ == value) return;
  alive_ = value;
  alive_changed_at_ = now;
}

std::optional<std::uint16_t> SimBench::alive() const {
  std::lock_guard<std::mutex> lock(mu_);
  return alive_;
}

void SimBench::Write(FixtureOutput output, bool on) {
  std::lock_guard<std::mutex> lock(mu_);
  const auto now = now_();
  // A dead controller cannot act on a command, except that its outputs drop to safe on their
  // own: a real PLC's excitation relay is wired fail-safe.
  if (FaultActiveLocked(SimFault::kStopsAnswering, now)) {
    if (excitation_) {
      excitation_ = false;
      excitation_off_at_ = now;
    }
    throw DeviceError(std::string("no answer from the fixture controller writing ") +
                      ToString(output) + " (simulated: stops_answering)");
  }
  ExpireAliveLocked(now);
  switch (output) {
    case FixtureOutput::kClampCmd:
      if (on != clamp_cmd_) {
        clamp_cmd_ = on;
        clamp_cmd_at_ = now;
      }
      break;
    case FixtureOutput::kExcitationEnable:
      // Without a fresh alive change the controller does not close the relay.
      if (on && !excitation_ && !AliveFreshLocked(now)) break;
      if (on && !excitation_ && fault_ && fault_->on_excitation && !fault_->triggered_at)
        fault_->triggered_at = now;
      if (!on && excitation_) excitation_off_at_ = now;
      excitation_ = on;
      break;
    case FixtureOutput::kLampPass:
      lamp_pass_ = on;
      break;
    case FixtureOutput::kLampFail:
      lamp_fail_ = on;
      break;
  }
}

void SimBench::SelectPhasePair(PhasePair pair) {
  std::lock_guard<std::mutex> lock(mu_);
  CheckAnsweringLocked(now_());
  pair_ = pair;
}

bool SimBench::output(FixtureOutput o) const {
  std::lock_guard<std::mutex> lock(mu_);
  ExpireAliveLocked(now_());
  switch (o) {
    case FixtureOutput::kClampCmd:
      return clamp_cmd_;
    case FixtureOutput::kExcitationEnable:
      return excitation_;
    case FixtureOutput::kLampPass:
      return lamp_pass_;
    case FixtureOutput::kLampFail:
      return lamp_fail_;
  }
  return false;
}

PhasePair SimBench::phase_pair() const {
  std::lock_guard<std::mutex> lock(mu_);
  return pair_;
}

bool SimBench::excitation_connected() const {
  std::lock_guard<std::mutex> lock(mu_);
  ExpireAliveLocked(now_());
  return excitation_;
}

std::optional<SimBench::Clock::time_point> SimBench::last_excitation_off() const {
  std::lock_guard<std::mutex> lock(mu_);
  ExpireAliveLocked(now_());
  return excitation_off_at_;
}

void SimBench::InjectFault(SimFault fault, std::chrono::milliseconds delay, bool on_excitation,
                           std::optional<std::chrono::milliseconds> duration) {
  std::lock_guard<std::mutex> lock(mu_);
  fault_ = PendingFault{fault, delay, on_excitation, now_(), duration, std::nullopt};
}

void SimBench::ClearFaults() {
  std::lock_guard<std::mutex> lock(mu_);
  fault_.reset();
}

bool SimBench::FaultActive(SimFault fault) const {
  std::lock_guard<std::mutex> lock(mu_);
  return FaultActiveLocked(fault, now_());
}

std::optional<SimBench::Clock::time_point> SimBench::fault_visible_at() const {
  std::lock_guard<std::mutex> lock(mu_);
  return FaultVisibleAtLocked();
}

}  // namespace eol::drivers
