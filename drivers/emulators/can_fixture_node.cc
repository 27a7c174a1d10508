#include "drivers/emulators/can_fixture_node.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

namespace eol::drivers {

CanFixtureNode::CanFixtureNode(std::shared_ptr<SimBench> bench, CanFixtureNodeSettings settings,
                               CanPortFactory open_port)
    : bench_(std::move(bench)), settings_(std::move(settings)), open_port_(std::move(open_port)) {
  if (!bench_) throw std::invalid_argument("CanFixtureNode: no bench");
  if (!open_port_) throw std::invalid_argument("CanFixtureNode: no port factory");
}

CanFixtureNode::~CanFixtureNode() { Stop(); }

Status CanFixtureNode::Start() {
  if (running()) return Status::Ok();
  const std::string where =
      "CAN fixture node " + std::to_string(settings_.map.node_id) + " on " + settings_.interface;
  std::string why;
  if (!settings_.map.IsValid(&why)) return Status::Error(where + ": " + why);
  if (settings_.status_period_ms < 1 || settings_.status_period_ms > 1000)
    return Status::Error(where + ": status_period_ms must be in 1..1000 (got " +
                         std::to_string(settings_.status_period_ms) + ")");
  try {
    port_ = open_port_(settings_.interface, {StandardDataFilter(settings_.map.command_id())});
  } catch (const std::exception& e) {
    return Status::Error(where + ": " + e.what());
  }
  stop_ = false;
  thread_ = std::thread([this] { Serve(); });
  spdlog::info(
      "fixture server: CAN node {} on {} (command 0x{:03X}, status 0x{:03X}, "
      "heartbeat 0x{:03X})",
      settings_.map.node_id, settings_.interface, settings_.map.command_id(),
      settings_.map.status_id(), settings_.map.heartbeat_id());
  return Status::Ok();
}

void CanFixtureNode::Stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  port_.reset();
}

void CanFixtureNode::Serve() {
  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::milliseconds(settings_.status_period_ms);
  auto next_status = Clock::now();
  auto next_heartbeat = Clock::now();
  std::optional<std::uint32_t> last_beat;
  bool relay_dropped_logged = false;
  while (!stop_) {
    try {
      const auto now = Clock::now();
      const auto wait =
          std::clamp(std::chrono::duration_cast<std::chrono::milliseconds>(next_status - now),
                     std::chrono::milliseconds(0), std::chrono::milliseconds(10));
      const std::optional<CanFrame> frame = port_->Receive(wait);
      if (bench_->FaultActive(SimFault::kStopsAnswering)) {
        // A dead controller: silent, deaf, and its excitation relay drops out.
        if (bench_->output(FixtureOutput::kExcitationEnable)) {
          try {
            bench_->Write(FixtureOutput::kExcitationEnable, false);
          } catch (const DeviceError&) {
          }
        }
        if (!relay_dropped_logged)
          spdlog::info(
              "fixture server: stops_answering: CAN node silent, excitation relay "
              "dropped out");
        relay_dropped_logged = true;
        continue;
      }
      if (frame) {
        Apply(*frame);
        SendStatus();
        next_status = Clock::now() + period;
      } else if (Clock::now() >= next_status) {
        SendStatus();
        next_status += period;
        if (next_status < Clock::now()) next_status = Clock::now() + period;
      }
      const std::uint32_t beat = bench_->PeekInputs().heartbeat;  // latches: status frames
      const bool frozen = bench_->FaultActive(SimFault::kHeartbeatFreezes);
      if (!frozen && (!last_beat || beat != *last_beat || Clock::now() >= next_heartbeat)) {
        SendHeartbeat(beat);
        last_beat = beat;
        next_heartbeat = Clock::now() + 2 * period;
      }
    } catch (const DeviceError& e) {
      // The bench stopped answering between two checks, or the interface failed.
      spdlog::debug("fixture server: CAN node: {}", e.what());
      if (!bench_->FaultActive(SimFault::kStopsAnswering)) {
        spdlog::error("fixture server: CAN node on {} stops: {}", settings_.interface, e.what());
        return;
      }
    }
  }
}

void CanFixtureNode::Apply(const CanFrame& f) {
  const CanMap& m = settings_.map;
  if (f.extended || f.remote || f.error || f.id != m.command_id()) return;
  if (f.dlc != m.Dlc(CanFrameKind::kCommand)) {
    spdlog::warn(
        "fixture server: CAN node: malformed {}: {} data bytes, expected {} ({}); "
        "not applied",
        m.Describe(CanFrameKind::kCommand), f.dlc, m.Dlc(CanFrameKind::kCommand), Describe(f));
    return;
  }
  const std::uint8_t* d = f.data.data();
  const unsigned pair = GetField(d, m.phase_pair);
  if (pair > 2) {
    spdlog::warn("fixture server: CAN node: {} with phase_pair {} (0..2 accepted); not applied",
                 m.Describe(CanFrameKind::kCommand), pair);
    return;
  }
  const bool clamp = GetField(d, m.clamp_cmd) != 0;
  if (clamp && settings_.load_part_on_clamp && !bench_->output(FixtureOutput::kClampCmd) &&
      !bench_->part()) {
    const std::string serial = "SIM-" + std::to_string(++parts_loaded_);
    bench_->LoadPart(serial);
    spdlog::info("fixture server: clamp closing on an empty fixture: loaded part {}", serial);
  }
  bench_->SelectPhasePair(static_cast<PhasePair>(pair));
  // Before the outputs: a frame that sets excitation_enable carries the fresh alive value.
  bench_->WriteAlive(static_cast<std::uint16_t>(GetField(d, m.station_alive)));
  bench_->Write(FixtureOutput::kClampCmd, clamp);
  // Every frame carries excitation_enable: only its rising edge is a command to close the
  // relay (can_map.h), so a relay the alive rule opened stays open until commanded again.
  const bool excite = GetField(d, m.excitation_enable) != 0;
  if (!excite || !excitation_cmd_) bench_->Write(FixtureOutput::kExcitationEnable, excite);
  excitation_cmd_ = excite;
  bench_->Write(FixtureOutput::kLampPass, GetField(d, m.lamp_pass) != 0);
  bench_->Write(FixtureOutput::kLampFail, GetField(d, m.lamp_fail) != 0);
}

void CanFixtureNode::SendStatus() {
  const CanMap& m = settings_.map;
  const FixtureInputs in = bench_->ReadInputs();
  CanFrame f;
  f.id = m.status_id();
  f.dlc = static_cast<std::uint8_t>(m.Dlc(CanFrameKind::kStatus));
  std::uint8_t* d = f.data.data();
  SetField(d, m.clamped, in.clamped);
  SetField(d, m.released, in.released);
  SetField(d, m.part_present, in.part_present);
  SetField(d, m.door_closed, in.door_closed);
  SetField(d, m.estop_ok, in.estop_ok);
  SetField(d, m.clamp_cmd_echo, bench_->output(FixtureOutput::kClampCmd));
  SetField(d, m.excitation_enable_echo, bench_->output(FixtureOutput::kExcitationEnable));
  SetField(d, m.lamp_pass_echo, bench_->output(FixtureOutput::kLampPass));
  SetField(d, m.lamp_fail_echo, bench_->output(FixtureOutput::kLampFail));
  SetField(d, m.phase_pair_echo, static_cast<unsigned>(bench_->phase_pair()));
  const double counts = std::round(in.clamp_pressure_bar / m.pressure_bar_per_count);
  SetField(d, m.clamp_pressure, static_cast<unsigned>(std::clamp(counts, 0.0, 65535.0)));
  SetField(d, m.status_counter, status_counter_++);
  port_->Send(f);
}

void CanFixtureNode::SendHeartbeat(std::uint32_t beat) {
  const CanMap& m = settings_.map;
  CanFrame f;
  f.id = m.heartbeat_id();
  f.dlc = static_cast<std::uint8_t>(m.Dlc(CanFrameKind::kHeartbeat));
  SetField(f.data.data(), m.nmt_state, kCanNmtOperational);
  SetField(f.data.data(), m.heartbeat, beat & 0xFFu);
  port_->Send(f);
}

}  // namespace eol::drivers
