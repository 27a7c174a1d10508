// What the HTTP server allows each kind of client (the reasons are in station/http/server.h).
// Apart from server.h so that HttpOptions can carry it without including httplib.
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
};

}  // namespace eol::station::http
