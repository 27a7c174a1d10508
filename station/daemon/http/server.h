// The HTTP server under the API: cpp-httplib's Server with a capacity that does not depend on
// long-lived or slow clients (issue 14: eight event streams or eight slow connections used to
// hold all eight workers and take the API down).
//
//   request workers  `request_workers` threads serve ordinary requests, one connection each.
//   event streams    a handler that will hold its connection (GET /api/events) calls
//                    BecomeStream(): its thread keeps the connection and a new worker takes
//                    its place, so streams never hold request workers. At most `max_streams`
//                    at once; beyond, BecomeStream() is false and the route answers 503.
//   queue            a connection that waited `max_queue_wait` for a worker is answered 503
//                    "overloaded" and closed without its request being read, so a request its
//                    client has given up on (a POST /api/tests that timed out) is never acted
//                    on later.
//   heads            no worker waits for a request's head: one thread reads every connection's
//                    head (and a body of up to `prefetch_body_bytes`) with a deadline and caps
//                    on head bytes, header lines and waiting connections per peer address
//                    (station/daemon/http/head_reader.h); a worker gets a connection with its head
//                    in hand, serves one request and gives a kept-alive connection back.
//   slow bodies      a body that is not prefetched (chunked, or above prefetch_body_bytes) is
//                    read by its worker: at most `max_body_readers_per_peer` workers read
//                    bodies of one peer address; one more is answered 503 unread.
//   deadlines        the rest of a body must arrive within `request_deadline` of the head, and
//                    each read or write within `io_timeout`; a slow client is cut off when
//                    either passes.
//   backlog          `listen_backlog` pending connections (httplib's built-in is 5).
//   one per port     no SO_REUSEPORT: a second server on a bound port fails to bind.
#pragma once

#include <httplib.h>

#include <string>

#include "station/daemon/http/head_reader.h"
#include "station/daemon/http/limits.h"

namespace eol::station::http {

// On a worker thread of an ApiServer: this thread keeps its connection as an event stream
// (no deadline; a new request worker takes its place). False at the maximum of streams or when
// the server is stopping, and off a server thread.
bool BecomeStream();

// On a worker thread of an ApiServer: the rest of this request's body is not read, so the
// connection is closed after the response (with a short drain, so the client reads it).
void CloseAfterResponse();

class ApiServer final : public httplib::Server {
 public:
  explicit ApiServer(ServerLimits limits);
  ~ApiServer() override;
  ApiServer(const ApiServer&) = delete;
  ApiServer& operator=(const ApiServer&) = delete;

  // Binds `host`:`port` (0: any free port) with the limits' backlog; the bound port, or -1
  // with the system's reason in *why.
  int Bind(const std::string& host, int port, std::string* why);
  const ServerLimits& limits() const { return limits_; }

 private:
  // Serves one connection as httplib does, but reading through a stream with the request's
  // deadline, refusing connections that waited too long for a worker, and closing after a
  // refused body.
  bool process_and_close_socket(::socket_t sock) override;
  // On a worker: one request whose head (station/daemon/http/head_reader.h) is in `bytes`; the
  // connection goes back to the head reader when kept alive.
  void ServeRequest(HeadReader::Ready ready);

  const ServerLimits limits_;
  int listen_fd_ = -1;  // the listening socket, seen by the socket-options hook
};

}  // namespace eol::station::http
