// The line PLC's handshake: the station as a Modbus TCP server (libmodbus) that the line PLC
// polls. The map and the handshake are in station/daemon/plc/plc_map.h.
//
// One thread serves every connected PLC (several at once, up to max_clients; one more is
// refused and closed at once) through drivers/fixture/modbus_tcp_server.h: non-blocking
// sockets, each request assembled per connection, so a slow or idle PLC stalls no other; a
// request must arrive whole within frame_deadline of its first byte and a connection without
// a request for idle_timeout is closed. Before each request and at least every 100 ms it
// refreshes the tables from the station
// (PlcBackend::view), and after a request that left the start coil set it takes the start:
// the serial is decoded and validated, the station asked to queue it, the refusal code
// written and the coil cleared, all before the next request of any client is served, so a
// PLC that reads start = 0 also reads the refusal of that start. A PLC that disconnects
// changes nothing: the test goes on, is stored, and the next connection reads its result.
// Requests for another unit id get exception 0x0B (gateway target failed to respond);
// function codes other than 1-6, 15 and 16 get 0x01 (illegal function); addresses outside
// the map get 0x02 (illegal data address, from libmodbus).
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "analysis/qc/measurement.h"
#include "station/daemon/plc/plc_map.h"
#include "station/daemon/test_request.h"

struct _modbus;
struct _modbus_mapping_t;

namespace eol::station::plc {

struct PlcServerSettings {
  // Dotted IPv4 address to listen on. Modbus has no authentication: the default is loopback
  // only; a station serves the line PLC on its address in the PLC network ("0.0.0.0" is
  // every interface, which the station logs as a warning).
  std::string listen = "127.0.0.1";
  int port = 502;   // 0: any free port (see PlcServer::port())
  int unit_id = 1;  // 1..247
  PlcMap map;
  int max_clients = 8;                             // connections served at once; more are refused
  std::chrono::milliseconds frame_deadline{1000};  // a request's first byte to its last
  std::chrono::milliseconds idle_timeout{60000};   // a connection without a request
};

// What the PLC sees of the station. Read under the station's own locks, so busy, verdicts
// and last_* are consistent with each other.
struct PlcStationView {
  bool busy = false;           // a test is waiting or running
  bool lockout = false;        // self-check lockout
  bool stopping = false;       // the station is shutting down
  std::uint64_t verdicts = 0;  // tests ended since start: stored, or refused by the sequencer
  std::uint64_t stored = 0;    // records stored since start
  std::optional<analysis::Outcome> last_outcome;    // of the newest verdict
  std::optional<analysis::ReasonCode> last_reason;  // its first reason, if any
};

struct PlcStartReply {
  PlcRefusal refusal = PlcRefusal::kNone;
  std::string message;                // why it was refused
  std::uint64_t verdicts_before = 0;  // PlcStationView::verdicts when it was accepted
};

// What the server asks of the station (Station::StartPlc wires these).
struct PlcBackend {
  std::function<PlcStartReply(const TestRequest& request)> start;
  std::function<PlcStationView()> view;
};

class PlcServer {
 public:
  PlcServer(PlcServerSettings settings, PlcBackend backend);
  ~PlcServer();  // Stop()
  PlcServer(const PlcServer&) = delete;
  PlcServer& operator=(const PlcServer&) = delete;
  PlcServer(PlcServer&&) = delete;
  PlcServer& operator=(PlcServer&&) = delete;

  // Binds, listens and serves on a thread of its own. Throws std::runtime_error naming the
  // address and the cause ("PLC server on 0.0.0.0:502: listen: Permission denied").
  void Start();
  // Closes every connection and the listening socket and joins the thread. Idempotent.
  void Stop();
  int port() const { return port_; }  // the port actually bound (after Start)

 private:
  void Serve();
  bool Handle(const std::uint8_t* request, int length);  // false: the reply was not sent
  void Refresh();
  void TakeStart();
  void CloseAll();
  std::string Where() const;

  const PlcServerSettings settings_;
  const PlcBackend backend_;
  _modbus* ctx_ = nullptr;
  _modbus_mapping_t* mapping_ = nullptr;
  int listen_fd_ = -1;
  int wake_[2] = {-1, -1};
  std::atomic<int> port_{0};
  std::thread thread_;
  // The serving thread's own: whether a start was accepted, and the verdict count then.
  bool accepted_ = false;
  std::uint64_t verdicts_at_accept_ = 0;
  PlcRefusal refusal_ = PlcRefusal::kNone;
};

}  // namespace eol::station::plc
