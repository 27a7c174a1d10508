// What the HTTP server allows each kind of client (the reasons are in
// station/daemon/http/server.h). Apart from server.h so that HttpOptions can carry it without
// including httplib.
#pragma once

#include <chrono>
#include <cstddef>

namespace eol::station::http {

struct ServerLimits {
  std::size_t request_workers = 16;
  std::size_t max_streams = 128;
  std::chrono::milliseconds max_queue_wait{2000};
  std::chrono::milliseconds request_deadline{10000};
  std::chrono::seconds io_timeout{5};
  std::chrono::seconds keep_alive_idle{2};  // an idle kept-alive connection is closed after
  int listen_backlog = 1024;                // capped by the kernel's net.core.somaxconn
  // Read before a worker is taken (station/daemon/http/head_reader.h):
  std::chrono::milliseconds head_deadline{5000};  // a request's head, from its first byte
  std::size_t max_head_bytes = 16 * 1024;         // request line and headers: 431 beyond
  std::size_t max_header_count = 64;              // header lines: 431 beyond
  std::size_t prefetch_body_bytes = 64 * 1024;    // a Content-Length body up to this is read too
  std::size_t max_waiting_per_peer = 256;         // connections of one address waiting for a head
  std::size_t max_waiting = 768;              // of all addresses (below 1024 descriptors in all)
  int max_requests_per_connection = 100;      // then Connection: close
  std::size_t max_body_readers_per_peer = 8;  // workers reading bodies of one address
};

}  // namespace eol::station::http
