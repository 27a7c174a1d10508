#include "station/daemon/plc/plc_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <modbus.h>
#include <netinet/in.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <initializer_list>
#include <stdexcept>
#include <utility>
#include <vector>

#include "db/serial_number.h"
#include "drivers/fixture/modbus_link.h"
#include "drivers/fixture/modbus_tcp_server.h"

namespace eol::station::plc {
namespace {

struct Range {
  int start = 0;
  int count = 0;
};

// The smallest table that holds `addresses` (first address and width of each signal).
Range Span(std::initializer_list<std::pair<int, int>> addresses) {
  int lo = 65536, hi = -1;
  for (const auto& [a, w] : addresses) {
    lo = std::min(lo, a);
    hi = std::max(hi, a + w - 1);
  }
  return Range{lo, hi - lo + 1};
}

}  // namespace

PlcServer::PlcServer(PlcServerSettings settings, PlcBackend backend)
    : settings_(std::move(settings)), backend_(std::move(backend)) {
  if (!backend_.start || !backend_.view) throw std::invalid_argument("PlcServer: no backend");
}

PlcServer::~PlcServer() { Stop(); }

std::string PlcServer::Where() const {
  return "PLC server on " + settings_.listen + ":" + std::to_string(settings_.port);
}

void PlcServer::Start() {
  if (thread_.joinable()) return;
  const auto fail = [&](const std::string& reason) {
    CloseAll();
    throw std::runtime_error(Where() + ": " + reason);
  };
  std::string why;
  if (!settings_.map.IsValid(&why)) fail("map: " + why);
  if (settings_.unit_id < 1 || settings_.unit_id > 247) fail("unit_id must be in [1, 247]");
  if (settings_.max_clients < 1) fail("max_clients must be >= 1");
  in_addr addr{};
  if (inet_pton(AF_INET, settings_.listen.c_str(), &addr) != 1)
    fail("listen must be a dotted IPv4 address");

  const PlcMap& m = settings_.map;
  const Range coils = Span({{m.start, 1}});
  const Range inputs = Span({{m.busy, 1}, {m.done, 1}, {m.ready, 1}, {m.lockout, 1}});
  const Range holding = Span({{m.serial, kSerialRegisters},
                              {m.operator_id, kOperatorIdRegisters},
                              {m.shift, kShiftRegisters},
                              {m.order_number, kOrderNumberRegisters},
                              {m.variant, 1}});
  const Range input_registers =
      Span({{m.result, 1}, {m.counter, 1}, {m.reason, 1}, {m.refusal, 1}});
  mapping_ = modbus_mapping_new_start_address(
      static_cast<unsigned>(coils.start), static_cast<unsigned>(coils.count),
      static_cast<unsigned>(inputs.start), static_cast<unsigned>(inputs.count),
      static_cast<unsigned>(holding.start), static_cast<unsigned>(holding.count),
      static_cast<unsigned>(input_registers.start), static_cast<unsigned>(input_registers.count));
  if (mapping_ == nullptr)
    fail(std::string("cannot allocate the mapping: ") + modbus_strerror(errno));

  ctx_ = modbus_new_tcp(settings_.listen.c_str(), settings_.port);
  if (ctx_ == nullptr) fail(std::string("modbus_new_tcp: ") + modbus_strerror(errno));
  listen_fd_ = modbus_tcp_listen(ctx_, settings_.max_clients);
  if (listen_fd_ == -1) fail(std::string("listen: ") + modbus_strerror(errno));
  sockaddr_in bound{};
  socklen_t len = sizeof bound;
  if (getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&bound), &len) != 0)
    fail(std::string("getsockname: ") + std::strerror(errno));
  port_ = ntohs(bound.sin_port);
  if (pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0) fail(std::string("pipe: ") + std::strerror(errno));
  Refresh();
  thread_ = std::thread([this] { Serve(); });
  spdlog::info("PLC server: Modbus TCP on {}:{} unit {}", settings_.listen, port_.load(),
               settings_.unit_id);
  if (settings_.listen == "0.0.0.0")
    spdlog::warn(
        "PLC server: listening on every interface (0.0.0.0); Modbus has no "
        "authentication: set plc.listen to the station's address in the PLC network");
}

void PlcServer::Stop() {
  if (thread_.joinable()) {
    const char byte = 'x';
    (void)!write(wake_[1], &byte, 1);
    thread_.join();
  }
  CloseAll();
}

void PlcServer::CloseAll() {
  if (listen_fd_ >= 0) close(listen_fd_);
  listen_fd_ = -1;
  if (ctx_ != nullptr) {
    modbus_set_socket(ctx_, -1);  // the client sockets were closed by Serve()
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

void PlcServer::Serve() {
  drivers::ModbusTcpLoopSettings loop_settings;
  loop_settings.name = "PLC server";
  loop_settings.max_clients = settings_.max_clients;
  loop_settings.frame_deadline = settings_.frame_deadline;
  loop_settings.idle_timeout = settings_.idle_timeout;
  drivers::ModbusTcpLoop loop(
      loop_settings,
      [this](int fd, const std::uint8_t* request, int length) {
        modbus_set_socket(ctx_, fd);
        try {
          return Handle(request, length);
        } catch (const std::exception& e) {
          spdlog::error("PLC server: request failed: {}", e.what());
          return true;
        }
      },
      [this] {
        try {
          Refresh();  // busy -> done shows within 100 ms even while no PLC asks
        } catch (const std::exception& e) {
          spdlog::error("PLC server: reading the station's state: {}", e.what());
        }
      });
  loop.Run(listen_fd_, wake_[0]);
}

bool PlcServer::Handle(const std::uint8_t* request, int length) {
  const int header = modbus_get_header_length(ctx_);
  if (length <= header) return true;
  const int unit = request[header - 1];
  const int function = request[header];
  if (unit != settings_.unit_id)
    return modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_GATEWAY_TARGET) >= 0;
  if (!drivers::IsPlainModbusFunction(function))
    return modbus_reply_exception(ctx_, request, MODBUS_EXCEPTION_ILLEGAL_FUNCTION) >= 0;
  Refresh();
  const int sent = modbus_reply(ctx_, request, length, mapping_);  // applies a write, answers
  const int coil = settings_.map.start - mapping_->start_bits;
  if (mapping_->tab_bits[coil] != 0) TakeStart();
  return sent >= 0;
}

void PlcServer::TakeStart() {
  const PlcMap& m = settings_.map;
  PlcStartReply reply;
  TestRequest r;
  std::string why;
  const auto text = [&](int address, int count, std::string* out) {
    return DecodeAscii(mapping_->tab_registers + (address - mapping_->start_registers), count, out,
                       &why);
  };
  if (!text(m.serial, kSerialRegisters, &r.serial)) {
    reply = {PlcRefusal::kBadSerial, "serial registers: " + why, 0};
  } else if (!db::ValidSerial(r.serial, &why)) {
    reply = {PlcRefusal::kBadSerial, "serial '" + r.serial + "': " + why, 0};
  } else if (!text(m.operator_id, kOperatorIdRegisters, &r.work.operator_id)) {
    reply = {PlcRefusal::kBadField, "operator_id registers: " + why, 0};
  } else if (!text(m.shift, kShiftRegisters, &r.work.shift)) {
    reply = {PlcRefusal::kBadField, "shift registers: " + why, 0};
  } else if (!text(m.order_number, kOrderNumberRegisters, &r.work.order_number)) {
    reply = {PlcRefusal::kBadField, "order_number registers: " + why, 0};
  } else if (!ValidWorkContext(r.work, &why)) {
    reply = {PlcRefusal::kBadField, why, 0};
  } else {
    r.variant.plc_code = mapping_->tab_registers[m.variant - mapping_->start_registers];
    reply = backend_.start(r);
  }
  refusal_ = reply.refusal;
  if (reply.refusal == PlcRefusal::kNone) {
    accepted_ = true;
    verdicts_at_accept_ = reply.verdicts_before;
    spdlog::info("PLC: start of serial '{}' accepted", r.serial);
  } else {
    spdlog::warn("PLC: start refused ({}): {}", ToString(reply.refusal), reply.message);
  }
  mapping_->tab_bits[m.start - mapping_->start_bits] = 0;
  Refresh();
}

void PlcServer::Refresh() {
  const PlcStationView v = backend_.view();
  const PlcMap& m = settings_.map;
  // The result of the accepted start, once its test has ended; before any PLC start, the
  // newest result of any test (HTTP, scanner).
  const bool ended = accepted_ && v.verdicts > verdicts_at_accept_;
  const bool show = accepted_ ? ended : v.last_outcome.has_value();
  const auto bit = [this](int address, bool on) {
    mapping_->tab_input_bits[address - mapping_->start_input_bits] = on ? 1 : 0;
  };
  const auto reg = [this](int address, std::uint16_t value) {
    mapping_->tab_input_registers[address - mapping_->start_input_registers] = value;
  };
  bit(m.busy, v.busy);
  bit(m.done, ended && !v.busy);
  bit(m.ready, !v.busy && !v.lockout && !v.stopping);
  bit(m.lockout, v.lockout);
  reg(m.result, show && v.last_outcome ? static_cast<std::uint16_t>(ToPlcResult(*v.last_outcome))
                                       : static_cast<std::uint16_t>(PlcResult::kNone));
  reg(m.counter, static_cast<std::uint16_t>(v.stored & 0xFFFFu));
  reg(m.reason, show && v.last_reason ? PlcReasonCode(*v.last_reason) : 0);
  reg(m.refusal, static_cast<std::uint16_t>(refusal_));
}

}  // namespace eol::station::plc
