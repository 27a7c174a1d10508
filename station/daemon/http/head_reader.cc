#include "station/daemon/http/head_reader.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "station/daemon/http/reply.h"

namespace eol::station::http {
namespace {

using Clock = std::chrono::steady_clock;

std::string PeerAddress(int fd) {
  sockaddr_storage a{};
  socklen_t len = sizeof a;
  char host[NI_MAXHOST] = "";
  if (getpeername(fd, reinterpret_cast<sockaddr*>(&a), &len) != 0 ||
      getnameinfo(reinterpret_cast<sockaddr*>(&a), len, host, sizeof host, nullptr, 0,
                  NI_NUMERICHOST) != 0)
    return "?";
  return host;
}

// The end of the head (after its empty line) in `b`, or npos.
std::size_t HeadEnd(const std::string& b) {
  const std::size_t crlf = b.find("\r\n\r\n");
  const std::size_t lf = b.find("\n\n");
  if (crlf == std::string::npos && lf == std::string::npos) return std::string::npos;
  return crlf < lf ? crlf + 4 : lf + 2;
}

// The body length to read with the head: a plain Content-Length up to `cap`, else 0.
std::size_t PrefetchLength(const std::string& head, std::size_t cap) {
  std::string lower(head);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.find("\ntransfer-encoding:") != std::string::npos) return 0;
  const std::size_t at = lower.find("\ncontent-length:");
  if (at == std::string::npos) return 0;
  std::size_t i = at + 16, n = 0;
  while (i < lower.size() && (lower[i] == ' ' || lower[i] == '\t')) ++i;
  const std::size_t digits = i;
  while (i < lower.size() && std::isdigit(static_cast<unsigned char>(lower[i])) && n <= cap)
    n = n * 10 + static_cast<std::size_t>(lower[i++] - '0');
  return i > digits && n <= cap ? n : 0;
}

// Whether a head announces a body (chunked, or a Content-Length other than 0).
bool HasBody(const std::string& head) {
  std::string lower(head);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (lower.find("\ntransfer-encoding:") != std::string::npos) return true;
  const std::size_t at = lower.find("\ncontent-length:");
  if (at == std::string::npos) return false;
  const std::size_t from = at + 16, line_end = lower.find('\n', from);
  return lower.substr(from, line_end - from).find_first_not_of(" \t\r0") != std::string::npos;
}

}  // namespace

struct HeadReader::Waiting {
  int fd = -1;
  std::string bytes;
  int served = 0;
  std::string peer;
  Clock::time_point deadline;
  std::size_t need = 0;       // once the head is in: the bytes to hold before dispatching
  bool body_pending = false;  // the head announces a body that is not prefetched
  bool counted = false;       // in per_peer_ and waiting_count_
  bool draining = false;      // refused: what it still sends is read and dropped until deadline
  bool done = false;
};

namespace {

void SetBlocking(int fd, bool blocking) {
  const int flags = fcntl(fd, F_GETFL);
  fcntl(fd, F_SETFL, blocking ? flags & ~O_NONBLOCK : flags | O_NONBLOCK);
}

}  // namespace

HeadReader::HeadReader(const ServerLimits& limits, Dispatch dispatch)
    : limits_(limits), dispatch_(std::move(dispatch)) {
  if (pipe2(wake_, O_CLOEXEC | O_NONBLOCK) != 0)
    throw std::runtime_error(std::string("http: pipe: ") + std::strerror(errno));
  thread_ = std::thread([this] { Run(); });
}

HeadReader::~HeadReader() { Stop(); }

void HeadReader::Stop() {
  {
    std::lock_guard<std::mutex> lock(mu_);
    stopping_ = true;
  }
  (void)!write(wake_[1], "x", 1);
  if (thread_.joinable()) thread_.join();
  std::lock_guard<std::mutex> lock(mu_);
  for (Waiting& w : inbox_) close(w.fd);
  inbox_.clear();
  for (int& fd : wake_) {
    if (fd >= 0) close(fd);
    fd = -1;
  }
}

HeadReader::Counts HeadReader::counts() const {
  std::lock_guard<std::mutex> lock(mu_);
  return counts_;
}

void HeadReader::Admit(int fd, std::string bytes, int served) {
  Waiting w;
  w.fd = fd;
  w.bytes = std::move(bytes);
  w.served = served;
  w.deadline = Clock::now() +
               (served > 0 && w.bytes.empty()
                    ? std::chrono::duration_cast<std::chrono::milliseconds>(limits_.keep_alive_idle)
                    : limits_.head_deadline);
  std::lock_guard<std::mutex> lock(mu_);
  if (stopping_) {
    close(fd);
    return;
  }
  inbox_.push_back(std::move(w));
  (void)!write(wake_[1], "x", 1);
}

void HeadReader::Run() {
  std::vector<Waiting> waiting;
  std::vector<pollfd> fds;
  for (;;) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (stopping_) break;
    }
    TakeInbox(waiting);
    Clock::time_point now = Clock::now(), wake_at = now + std::chrono::seconds(1);
    for (Waiting& w : waiting) {
      if (!w.done && now >= w.deadline) {
        if (!w.draining) {
          std::lock_guard<std::mutex> lock(mu_);
          ++counts_.timed_out;
        }
        Forget(w);
      }
      if (!w.done) wake_at = std::min(wake_at, w.deadline);
    }
    std::erase_if(waiting, [](const Waiting& w) { return w.done; });
    fds.assign(1, pollfd{wake_[0], POLLIN, 0});
    for (const Waiting& w : waiting) fds.push_back({w.fd, POLLIN, 0});
    const auto ms = std::chrono::ceil<std::chrono::milliseconds>(wake_at - now).count();
    const int n = poll(fds.data(), fds.size(), static_cast<int>(std::max<long long>(ms, 0)));
    if (n < 0 && errno != EINTR) {
      spdlog::error("http: head reader: poll: {}", std::strerror(errno));
      break;
    }
    if (n <= 0) continue;
    if (fds[0].revents != 0) {
      char sink[64];
      while (read(wake_[0], sink, sizeof sink) > 0) {
      }
    }
    // fds[1 + i] is waiting[i] for the connections this poll covered only.
    for (std::size_t i = 0; i + 1 < fds.size(); ++i)
      if (fds[1 + i].revents != 0) Read(waiting[i]);
    std::erase_if(waiting, [](const Waiting& w) { return w.done; });
    LogRefusals(false);
  }
  LogRefusals(true);
  for (Waiting& w : waiting) close(w.fd);
}

void HeadReader::TakeInbox(std::vector<Waiting>& waiting) {
  std::vector<Waiting> in;
  {
    std::lock_guard<std::mutex> lock(mu_);
    in.swap(inbox_);
  }
  for (Waiting& w : in) {
    w.peer = PeerAddress(w.fd);
    std::size_t& mine = per_peer_[w.peer];
    if (mine >= limits_.max_waiting_per_peer || waiting_count_ >= limits_.max_waiting) {
      const std::string why = mine >= limits_.max_waiting_per_peer
                                  ? "too many connections from " + w.peer + " wait for a request"
                                  : "too many connections wait for a request";
      if (mine == 0) per_peer_.erase(w.peer);
      Refuse(w, 503, "Service Unavailable", why);
      continue;
    }
    ++mine;
    ++waiting_count_;
    w.counted = true;
    SetBlocking(w.fd, false);
    if (!w.bytes.empty()) {
      Read(w);  // a pipelined request may be complete already
      if (w.done) continue;
    }
    waiting.push_back(std::move(w));
  }
}

// One read; dispatches the connection when its head (and prefetched body) is in.
bool HeadReader::Read(Waiting& w) {
  char buf[4096];
  if (w.draining) {
    const ssize_t n = recv(w.fd, buf, sizeof buf, 0);
    if (n == 0 || (n < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) Forget(w);
    return !w.done;
  }
  std::size_t room = sizeof buf;
  if (w.need > 0) room = std::min(room, w.need - std::min(w.need, w.bytes.size()));
  ssize_t got = 0;
  if (w.need == 0 || w.bytes.size() < w.need) {
    // A pipelined request's bytes may be in hand already: look at them before reading.
    if (!w.bytes.empty() && w.need == 0 && HeadEnd(w.bytes) != std::string::npos) {
      got = 0;
    } else {
      got = recv(w.fd, buf, room, 0);
      if (got == 0 || (got < 0 && errno != EAGAIN && errno != EWOULDBLOCK && errno != EINTR)) {
        Forget(w);
        return false;
      }
      if (got > 0) w.bytes.append(buf, static_cast<std::size_t>(got));
    }
  }
  if (w.need == 0) {
    const std::size_t end = HeadEnd(w.bytes);
    const std::size_t head = end == std::string::npos ? w.bytes.size() : end;
    const auto lines = static_cast<std::size_t>(
        std::count(w.bytes.begin(), w.bytes.begin() + static_cast<long>(head), '\n'));
    if (head > limits_.max_head_bytes || lines > limits_.max_header_count + 2) {
      Refuse(w, 431, "Request Header Fields Too Large",
             "the request head exceeds " + std::to_string(limits_.max_head_bytes) + " bytes or " +
                 std::to_string(limits_.max_header_count) + " header lines");
      return false;
    }
    if (end == std::string::npos) return true;
    w.need = end + PrefetchLength(w.bytes.substr(0, end), limits_.prefetch_body_bytes);
    w.body_pending = w.need == end && HasBody(w.bytes.substr(0, end));
  }
  if (w.bytes.size() < w.need) return true;
  {
    std::lock_guard<std::mutex> lock(mu_);
    ++counts_.dispatched;
  }
  Ready ready{w.fd, std::move(w.bytes), w.served, w.peer, w.body_pending};
  w.fd = -1;
  Forget(w);
  SetBlocking(ready.fd, true);  // the workers' stream waits with poll(), writes whole responses
  dispatch_(std::move(ready));
  return false;
}

void HeadReader::Refuse(Waiting& w, int status, const char* reason, const std::string& message) {
  const std::string reply =
      RawErrorResponse(status, reason, "http_" + std::to_string(status), message, false);
  (void)send(w.fd, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  {
    std::lock_guard<std::mutex> lock(mu_);
    ++(status == 431 ? counts_.refused_head : counts_.refused_busy);
  }
  ++unlogged_;
  if (!w.counted) {
    Forget(w);
    return;
  }
  // Read and drop what it still sends for a moment, so that it reads the answer rather than
  // a reset (closing with unread data resets the connection).
  shutdown(w.fd, SHUT_WR);
  std::string().swap(w.bytes);
  w.draining = true;
  w.deadline = Clock::now() + std::chrono::milliseconds(500);
}

// Closes (unless dispatched) and uncounts a waiting connection.
void HeadReader::Forget(Waiting& w) {
  if (w.fd >= 0) {
    shutdown(w.fd, SHUT_RDWR);
    close(w.fd);
  }
  w.fd = -1;
  w.done = true;
  if (!w.counted) return;
  w.counted = false;
  const auto it = per_peer_.find(w.peer);
  if (it != per_peer_.end() && --it->second == 0) per_peer_.erase(it);
  --waiting_count_;
}

void HeadReader::LogRefusals(bool flush) {
  if (unlogged_ == 0) return;
  const Clock::time_point now = Clock::now();
  if (!flush && now - logged_at_ < std::chrono::seconds(1)) return;
  const Counts c = counts();
  spdlog::warn(
      "http: refused {} connection(s) waiting for their request (in all: {} over a waiting "
      "cap, {} with an oversized head, {} past the head deadline)",
      unlogged_, c.refused_busy, c.refused_head, c.timed_out);
  unlogged_ = 0;
  logged_at_ = now;
}

}  // namespace eol::station::http
