#include "drivers/emulators/modbus_fixture_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <optional>
#include <vector>

#include "drivers/fixture/modbus_tcp_server.h"

namespace eol::drivers {

namespace {

// One value a write request puts into a table.
struct TableWrite {
  ModbusTable table;
  int address;
  int value;
};

// The writes a request carries (empty for a read). nullopt when the request is malformed:
// libmodbus answers it with an exception and nothing reaches the bench.
std::optional<std::vector<TableWrite>> DecodeWrites(const std::uint8_t* pdu, int n) {
  const auto u16 = [pdu](int i) { return (pdu[i] << 8) | pdu[i + 1]; };
  std::vector<TableWrite> out;
  switch (pdu[0]) {
    case MODBUS_FC_WRITE_SINGLE_COIL: {
      if (n < 5) return std::nullopt;
      const int v = u16(3);
      if (v != 0xFF00 && v != 0x0000) return std::nullopt;
      out.push_back({ModbusTable::kCoil, u16(1), v != 0 ? 1 : 0});
      return out;
    }
    case MODBUS_FC_WRITE_SINGLE_REGISTER:
      if (n < 5) return std::nullopt;
      out.push_back({ModbusTable::kHoldingRegister, u16(1), u16(3)});
      return out;
    case MODBUS_FC_WRITE_MULTIPLE_COILS: {
      if (n < 6) return std::nullopt;
      const int address = u16(1), count = u16(3), bytes = pdu[5];
      if (count < 1 || count > MODBUS_MAX_WRITE_BITS || bytes != (count + 7) / 8 || n < 6 + bytes)
        return std::nullopt;
      for (int i = 0; i < count; ++i)
        out.push_back({ModbusTable::kCoil, address + i, (pdu[6 + i / 8] >> (i % 8)) & 1});
      return out;
    }
    case MODBUS_FC_WRITE_MULTIPLE_REGISTERS: {
      if (n < 6) return std::nullopt;
      const int address = u16(1), count = u16(3), bytes = pdu[5];
      if (count < 1 || count > MODBUS_MAX_WRITE_REGISTERS || bytes != 2 * count || n < 6 + bytes)
        return std::nullopt;
      for (int i = 0; i < count; ++i)
        out.push_back({ModbusTable::kHoldingRegister, address + i, u16(6 + 2 * i)});
      return out;
    }
    default:
      return out;
  }
}

struct Range {
  int start = 0;
  int count = 0;
};

Range TableRange(const ModbusMap& map, ModbusTable table) {
  int lo = 65536, hi = -1;
  for (const ModbusSignalSpec& spec : ModbusSignals()) {
    const ModbusSignal& s = map.*(spec.member);
    if (s.table != table) continue;
    lo = std::min(lo, s.address);
    hi = std::max(hi, s.address);
  }
  return hi < 0 ? Range{} : Range{lo, hi - lo + 1};
}

std::optional<FixtureOutput> OutputOf(const ModbusSignalSpec& spec) {
  if (spec.member == &ModbusMap::clamp_cmd) return FixtureOutput::kClampCmd;
  if (spec.member == &ModbusMap::excitation_enable) return FixtureOutput::kExcitationEnable;
  if (spec.member == &ModbusMap::lamp_pass) return FixtureOutput::kLampPass;
  if (spec.member == &ModbusMap::lamp_fail) return FixtureOutput::kLampFail;
  return std::nullopt;
}

// The output signal (one of the station's writes) at a table address, if any.
const ModbusSignalSpec* OutputAt(const ModbusMap& map, ModbusTable table, int address) {
  for (const ModbusSignalSpec& spec : ModbusSignals()) {
    if (spec.kind != ModbusSignalKind::kBoolOutput && spec.kind != ModbusSignalKind::kWordOutput)
      continue;
    const ModbusSignal& s = map.*(spec.member);
    if (s.table == table && s.address == address) return &spec;
  }
  return nullptr;
}

// The addresses a read request covers; nullopt for anything else.
struct ReadRequest {
  ModbusTable table;
  int first;
  int count;
};
std::optional<ReadRequest> ReadRange(const std::uint8_t* pdu, int n) {
  if (n < 5) return std::nullopt;
  const int first = (pdu[1] << 8) | pdu[2], count = (pdu[3] << 8) | pdu[4];
  switch (pdu[0]) {
    case MODBUS_FC_READ_COILS:
      return ReadRequest{ModbusTable::kCoil, first, count};
    case MODBUS_FC_READ_DISCRETE_INPUTS:
      return ReadRequest{ModbusTable::kDiscreteInput, first, count};
    case MODBUS_FC_READ_HOLDING_REGISTERS:
      return ReadRequest{ModbusTable::kHoldingRegister, first, count};
    case MODBUS_FC_READ_INPUT_REGISTERS:
      return ReadRequest{ModbusTable::kInputRegister, first, count};
    default:
      return std::nullopt;
  }
}

// The clear-on-read interlock latches (modbus_map.h), by signal.
constexpr std::pair<ModbusSignal ModbusMap::*, SimLatch> kLatchedInputs[] = {
    {&ModbusMap::clamped, SimLatch::kClamped},
    {&ModbusMap::door_closed, SimLatch::kDoorClosed},
    {&ModbusMap::estop_ok, SimLatch::kEstopOk},
    {&ModbusMap::clamp_pressure, SimLatch::kClampPressure},
};

}  // namespace

ModbusFixtureServer::ModbusFixtureServer(std::shared_ptr<SimBench> bench,
                                         ModbusFixtureServerSettings settings)
    : bench_(std::move(bench)), settings_(std::move(settings)) {
  if (!bench_) throw std::invalid_argument("ModbusFixtureServer: no bench");
}

ModbusFixtureServer::~ModbusFixtureServer() { Stop(); }

Status ModbusFixtureServer::Start() {
  if (running()) return Status::Ok();
  const ModbusLink& link = settings_.link;
  const bool tcp = link.transport == ModbusLink::Transport::kTcp;
  const std::string where =
      tcp ? "Modbus TCP server on " + link.host + ":" + std::to_string(link.port)
          : "Modbus RTU server on " + link.Describe();
  std::string why;
  if (!link.IsValid(&why) || !settings_.map.IsValid(&why)) return Status::Error(where + ": " + why);
  if (settings_.max_clients < 1) return Status::Error(where + ": max_clients must be >= 1");

  const auto fail = [&](const std::string& reason) {
    CloseAll();
    return Status::Error(where + ": " + reason);
  };
  const Range bits = TableRange(settings_.map, ModbusTable::kCoil);
  const Range input_bits = TableRange(settings_.map, ModbusTable::kDiscreteInput);
  const Range registers = TableRange(settings_.map, ModbusTable::kHoldingRegister);
  const Range input_registers = TableRange(settings_.map, ModbusTable::kInputRegister);
  mapping_ = modbus_mapping_new_start_address(
      static_cast<unsigned>(bits.start), static_cast<unsigned>(bits.count),
      static_cast<unsigned>(input_bits.start), static_cast<unsigned>(input_bits.count),
      static_cast<unsigned>(registers.start), static_cast<unsigned>(registers.count),
      static_cast<unsigned>(input_registers.start), static_cast<unsigned>(input_registers.count));
  if (mapping_ == nullptr)
    return fail(std::string("cannot allocate the mapping: ") + modbus_strerror(errno));

  if (tcp) {
    in_addr addr{};
    if (inet_pton(AF_INET, link.host.c_str(), &addr) != 1)
      return fail("host must be a dotted IPv4 address to listen on");
    ctx_ = modbus_new_tcp(link.host.c_str(), link.port);
    if (ctx_ == nullptr) return fail(std::string("modbus_new_tcp: ") + modbus_strerror(errno));
    listen_fd_ = modbus_tcp_listen(ctx_, settings_.max_clients);
    if (listen_fd_ == -1) return fail(std::string("listen: ") + modbus_strerror(errno));
    sockaddr_in bound{};
    socklen_t len = sizeof bound;
    if (getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len) != 0)
      return fail(std::string("getsockname: ") + std::strerror(errno));
    port_ = ntohs(bound.sin_port);
  } else {
    ctx_ =
        modbus_new_rtu(link.device.c_str(), link.baud, link.parity, link.data_bits, link.stop_bits);
    if (ctx_ == nullptr) return fail(std::string("modbus_new_rtu: ") + modbus_strerror(errno));
    if (modbus_set_slave(ctx_, link.unit_id) == -1)
      return fail(std::string("unit id: ") + modbus_strerror(errno));
    if (modbus_connect(ctx_) == -1) return fail(std::string("open: ") + modbus_strerror(errno));
  }
  if (pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0)
    return fail(std::string("pipe: ") + std::strerror(errno));

  thread_ = std::thread([this] { Serve(); });
  if (tcp) {
    spdlog::info("fixture server: Modbus TCP on {}:{} unit {}", link.host, port_.load(),
                 link.unit_id);
  } else {
    spdlog::info("fixture server: Modbus RTU on {}", link.Describe());
  }
  return Status::Ok();
}

void ModbusFixtureServer::Stop() {
  if (thread_.joinable()) {
    const char byte = 'x';
    (void)!write(wake_[1], &byte, 1);
    thread_.join();
  }
  CloseAll();
}

void ModbusFixtureServer::CloseAll() {
  if (listen_fd_ >= 0) close(listen_fd_);
  listen_fd_ = -1;
  if (ctx_ != nullptr) {
    if (settings_.link.transport == ModbusLink::Transport::kTcp) {
      modbus_set_socket(ctx_, -1);  // the client sockets were closed by Serve()
    } else {
      modbus_close(ctx_);
    }
    modbus_free(ctx_);
    ctx_ = nullptr;
  }
  if (mapping_ != nullptr) modbus_mapping_free(mapping_);
  mapping_ = nullptr;
  for (int& fd : wake_) {
    if (fd >= 0) close(fd);
    fd = -1;
  }
}

void ModbusFixtureServer::Serve() {
  relay_dropped_logged_ = false;
  if (settings_.link.transport == ModbusLink::Transport::kTcp) {
    ModbusTcpLoopSettings loop_settings;
    loop_settings.name = "fixture server";
    loop_settings.max_clients = settings_.max_clients;
    loop_settings.frame_deadline = settings_.frame_deadline;
    loop_settings.idle_timeout = settings_.idle_timeout;
    ModbusTcpLoop loop(
        loop_settings,
        [this](int fd, const std::uint8_t* request, int length) {
          modbus_set_socket(ctx_, fd);
          Handle(request, length);
          return true;  // a reply that could not be sent: the loop's unread-reply check
        },
        [this] { DropRelayIfSilent(); });
    loop.Run(listen_fd_, wake_[0]);
    return;
  }
  ServeRtu();
}

// A controller that stops answering drops its excitation relay on its own.
void ModbusFixtureServer::DropRelayIfSilent() {
  if (!bench_->FaultActive(SimFault::kStopsAnswering) ||
      !bench_->output(FixtureOutput::kExcitationEnable))
    return;
  try {
    bench_->Write(FixtureOutput::kExcitationEnable, false);
  } catch (const DeviceError&) {
  }
  if (!relay_dropped_logged_)
    spdlog::info("fixture server: stops_answering: excitation relay dropped out");
  relay_dropped_logged_ = true;
}

void ModbusFixtureServer::ServeRtu() {
  const int io_fd = modbus_get_socket(ctx_);
  std::vector<std::uint8_t> request(MODBUS_MAX_ADU_LENGTH);
  bool serial_down = false;  // the serial line hung up: poll it again only after a pause
  for (;;) {
    std::vector<pollfd> fds;
    fds.push_back({wake_[0], POLLIN, 0});
    if (!serial_down) fds.push_back({io_fd, POLLIN, 0});
    const int n = poll(fds.data(), fds.size(), serial_down ? 200 : 100);
    if (n < 0 && errno != EINTR) {
      spdlog::error("fixture server: poll: {}", std::strerror(errno));
      break;
    }
    serial_down = false;
    DropRelayIfSilent();
    if (n <= 0) continue;
    if (fds[0].revents != 0) break;
    if (fds.size() < 2 || fds[1].revents == 0) continue;
    const int rc = modbus_receive(ctx_, request.data());
    if (rc > 0) {
      Handle(request.data(), rc);
    } else if (rc == -1) {
      const int err = errno;
      spdlog::debug("fixture server: RTU receive: {}", modbus_strerror(err));
      if (err != EMBBADCRC && err != EMBBADDATA && err != EMBMDATA && err != ETIMEDOUT &&
          err != EMBBADSLAVE)
        serial_down = true;
      modbus_flush(ctx_);
    }
  }
}

void ModbusFixtureServer::Handle(const unsigned char* request, int length) {
  const bool tcp = settings_.link.transport == ModbusLink::Transport::kTcp;
  const int header = modbus_get_header_length(ctx_);
  if (length <= header) return;
  if (bench_->FaultActive(SimFault::kStopsAnswering)) return;  // not a word back
  const int unit = request[header - 1];
  const int function = request[header];
  if (tcp && unit != settings_.link.unit_id) {
    modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_GATEWAY_TARGET);
    return;
  }
  if (!IsPlainModbusFunction(function)) {
    modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_ILLEGAL_FUNCTION);
    return;
  }
  try {
    const auto refreshed_at = bench_->now();
    RefreshMapping();
    ClearLatchesRead(request + header, length - header, refreshed_at);
    const auto writes = DecodeWrites(request + header, length - header);
    const auto in_mapping = [this](const TableWrite& w) {
      const bool coil = w.table == ModbusTable::kCoil;
      const int start = coil ? mapping_->start_bits : mapping_->start_registers;
      const int count = coil ? mapping_->nb_bits : mapping_->nb_registers;
      return w.address >= start && w.address < start + count;
    };
    if (writes && std::all_of(writes->begin(), writes->end(), in_mapping)) {
      for (const TableWrite& w : *writes) {
        const ModbusSignalSpec* spec = OutputAt(settings_.map, w.table, w.address);
        if (spec != nullptr && spec->member == &ModbusMap::phase_pair && w.value > 2) {
          modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_ILLEGAL_DATA_VALUE);
          return;
        }
      }
      for (const TableWrite& w : *writes) {
        const ModbusSignalSpec* spec = OutputAt(settings_.map, w.table, w.address);
        if (spec == nullptr) continue;
        if (spec->member == &ModbusMap::phase_pair) {
          bench_->SelectPhasePair(static_cast<PhasePair>(w.value));
          continue;
        }
        if (spec->member == &ModbusMap::station_alive) {
          bench_->WriteAlive(static_cast<std::uint16_t>(w.value));
          continue;
        }
        const FixtureOutput output = *OutputOf(*spec);
        const bool on = w.value != 0;
        if (output == FixtureOutput::kClampCmd && on && settings_.load_part_on_clamp &&
            !bench_->output(FixtureOutput::kClampCmd) && !bench_->part()) {
          const std::string serial = "SIM-" + std::to_string(++parts_loaded_);
          bench_->LoadPart(serial);
          spdlog::info("fixture server: clamp closing on an empty fixture: loaded part {}", serial);
        }
        bench_->Write(output, on);
      }
    }
  } catch (const DeviceError&) {
    return;  // the controller died while handling the request: no answer
  }
  modbus_reply(ctx_, request, length, mapping_);
}

void ModbusFixtureServer::ClearLatchesRead(const unsigned char* pdu, int n,
                                           SimBench::Clock::time_point as_of) {
  const auto range = ReadRange(pdu, n);
  if (!range) return;
  for (const auto& [member, latch] : kLatchedInputs) {
    const ModbusSignal& s = settings_.map.*member;
    if (s.table == range->table && s.address >= range->first &&
        s.address < range->first + range->count)
      bench_->ClearLatch(latch, as_of);
  }
}

void ModbusFixtureServer::RefreshMapping() {
  const FixtureInputs in = bench_->PeekInputs();
  const ModbusMap& map = settings_.map;
  for (const ModbusSignalSpec& spec : ModbusSignals()) {
    int value = 0;
    const auto m = spec.member;
    if (const auto output = OutputOf(spec)) {
      value = bench_->output(*output) ? 1 : 0;
    } else if (m == &ModbusMap::phase_pair) {
      value = static_cast<int>(bench_->phase_pair());
    } else if (m == &ModbusMap::station_alive) {
      value = bench_->alive().value_or(0);
    } else if (m == &ModbusMap::clamped) {
      value = in.clamped;
    } else if (m == &ModbusMap::released) {
      value = in.released;
    } else if (m == &ModbusMap::part_present) {
      value = in.part_present;
    } else if (m == &ModbusMap::door_closed) {
      value = in.door_closed;
    } else if (m == &ModbusMap::estop_ok) {
      value = in.estop_ok;
    } else if (m == &ModbusMap::clamp_pressure) {
      const double counts = std::round(in.clamp_pressure_bar / map.pressure_bar_per_count);
      value = static_cast<int>(std::clamp(counts, 0.0, 65535.0));
    } else if (m == &ModbusMap::heartbeat) {
      value = static_cast<int>(in.heartbeat & 0xFFFFu);
    }
    const ModbusSignal& s = map.*m;
    switch (s.table) {
      case ModbusTable::kCoil:
        mapping_->tab_bits[s.address - mapping_->start_bits] = value != 0;
        break;
      case ModbusTable::kDiscreteInput:
        mapping_->tab_input_bits[s.address - mapping_->start_input_bits] = value != 0;
        break;
      case ModbusTable::kHoldingRegister:
        mapping_->tab_registers[s.address - mapping_->start_registers] =
            static_cast<std::uint16_t>(value);
        break;
      case ModbusTable::kInputRegister:
        mapping_->tab_input_registers[s.address - mapping_->start_input_registers] =
            static_cast<std::uint16_t>(value);
        break;
    }
  }
}

}  // namespace eol::drivers
