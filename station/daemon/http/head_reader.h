// Reads each HTTP request's head (and a small body) on one thread with poll(), before a
// request worker is taken (sixteen slow connections, one per worker, timed the API
// out; two hundred answered /api/status once in fourteen tries). A connection reaches a
// worker only with its whole head (request line and headers, up to the empty line) and, when
// it has a Content-Length of at most `prefetch_body_bytes`, its whole body, in hand.
//
//   deadline     the head (and prefetched body) must be complete within `head_deadline` of
//                the connection's admission; a kept-alive connection may first stay idle for
//                `keep_alive_idle`. Past it the connection is closed.
//   head caps    more than `max_head_bytes` before the empty line, or more than
//                `max_header_count` header lines: 431 "Request Header Fields Too Large" and
//                closed (nothing of it is kept).
//   waiting caps at most `max_waiting_per_peer` connections of one address and `max_waiting`
//                in all wait for their head; one more is answered 503 and closed at once.
//
// Memory is bounded by max_waiting * (max_head_bytes + prefetch_body_bytes). Refusals are
// logged at most once a second, with their count.
#pragma once

#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "station/daemon/http/limits.h"

namespace eol::station::http {

class HeadReader {
 public:
  // A connection with its head read: the socket, the bytes read so far (the head, a body or
  // part of it, maybe the start of a pipelined request), the requests it already served, the
  // peer's address and whether a body is still to be read (chunked, or a Content-Length
  // above prefetch_body_bytes).
  struct Ready {
    int fd = -1;
    std::string bytes;
    int served = 0;
    std::string peer;
    bool body_pending = false;
  };
  using Dispatch = std::function<void(Ready ready)>;

  HeadReader(const ServerLimits& limits, Dispatch dispatch);
  ~HeadReader();  // Stop()
  HeadReader(const HeadReader&) = delete;
  HeadReader& operator=(const HeadReader&) = delete;

  // Takes `fd` (from accept, or back from a worker after a kept-alive response with what it
  // had read beyond that request). Any thread; after Stop() the socket is closed.
  void Admit(int fd, std::string bytes = {}, int served = 0);
  // Closes every waiting connection and joins the thread. Idempotent.
  void Stop();

  struct Counts {
    std::uint64_t dispatched = 0, refused_busy = 0, refused_head = 0, timed_out = 0;
  };
  Counts counts() const;

 private:
  struct Waiting;
  void Run();
  void TakeInbox(std::vector<Waiting>& waiting);
  bool Read(Waiting& w);  // false: closed (refused or gone)
  void Refuse(Waiting& w, int status, const char* reason, const std::string& message);
  void Forget(Waiting& w);
  void LogRefusals(bool flush);

  const ServerLimits limits_;
  const Dispatch dispatch_;
  int wake_[2] = {-1, -1};
  std::thread thread_;
  mutable std::mutex mu_;
  bool stopping_ = false;
  std::vector<Waiting> inbox_;
  std::unordered_map<std::string, std::size_t> per_peer_;  // the thread's own
  std::size_t waiting_count_ = 0;                          // the thread's own
  Counts counts_;                                          // under mu_
  std::uint64_t unlogged_ = 0;
  std::chrono::steady_clock::time_point logged_at_{};
};

}  // namespace eol::station::http
