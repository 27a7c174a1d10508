#include "station/daemon/http/server.h"

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <functional>
#include <list>
#include <unordered_map>
#include <vector>

#include "station/daemon/http/head_reader.h"
#include "station/daemon/http/reply.h"

namespace eol::station::http {
namespace {

using Clock = std::chrono::steady_clock;

class ConnectionPool;

// Set on each pool thread; what BecomeStream() and CloseAfterResponse() act on.
thread_local ConnectionPool* tl_pool = nullptr;
thread_local bool tl_is_stream = false;
thread_local bool tl_close_after_response = false;
thread_local Clock::duration tl_waited{};
// On httplib's accept thread while it hands over a socket: the pool whose reader takes it.
thread_local ConnectionPool* tl_admitting = nullptr;

int PollOne(int fd, short events, Clock::duration timeout) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(timeout).count();
  pollfd p{fd, events, 0};
  int r;
  do {
    r = ::poll(&p, 1, static_cast<int>(std::clamp<long long>(ms, 0, 1 << 30)));
  } while (r < 0 && errno == EINTR);
  return r;
}

// Threads serving connections: `workers` of them take connections from the queue; a thread
// that became an event stream leaves the pool when its connection ends, and a new worker has
// already taken its place. httplib creates one per listen and deletes it after shutdown().
class ConnectionPool final : public httplib::TaskQueue {
 public:
  using Serve = std::function<void(HeadReader::Ready ready)>;

  ConnectionPool(const ServerLimits& limits, Serve serve)
      : limits_(limits), reader_(limits, [this, serve](HeadReader::Ready ready) {
          Enqueue([serve, ready = std::move(ready)]() mutable { serve(std::move(ready)); });
        }) {
    std::lock_guard<std::mutex> lock(mu_);
    for (std::size_t i = 0; i < limits_.request_workers; ++i)
      threads_.emplace_back([this] { Work(); });
  }
  ~ConnectionPool() override { shutdown(); }

  // httplib's accept thread, with a job that serves one socket: run here, the job gives the
  // socket to the head reader (ApiServer::process_and_close_socket), no worker is taken.
  void enqueue(std::function<void()> fn) override {
    tl_admitting = this;
    fn();
    tl_admitting = nullptr;
  }
  HeadReader& reader() { return reader_; }

  // A worker reading a body that was not prefetched, for `peer`: false when that peer has
  // max_body_readers_per_peer workers reading bodies already.
  bool TakeBodyReader(const std::string& peer) {
    std::lock_guard<std::mutex> lock(mu_);
    std::size_t& n = body_readers_[peer];
    if (n >= limits_.max_body_readers_per_peer) return false;
    ++n;
    return true;
  }
  void ReleaseBodyReader(const std::string& peer) {
    std::lock_guard<std::mutex> lock(mu_);
    const auto it = body_readers_.find(peer);
    if (it != body_readers_.end() && --it->second == 0) body_readers_.erase(it);
  }

  void shutdown() override {
    reader_.Stop();
    {
      std::lock_guard<std::mutex> lock(mu_);
      stopping_ = true;
    }
    cv_.notify_all();
    for (;;) {
      std::list<std::thread> threads;
      {
        std::lock_guard<std::mutex> lock(mu_);
        threads.swap(threads_);
        finished_.clear();
      }
      if (threads.empty()) return;
      for (auto& t : threads) t.join();
    }
  }

  void Enqueue(std::function<void()> fn) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      jobs_.push_back({std::move(fn), Clock::now()});
    }
    cv_.notify_one();
  }

  bool BecomeStream() {
    std::lock_guard<std::mutex> lock(mu_);
    if (stopping_ || streams_ >= limits_.max_streams) return false;
    ++streams_;
    tl_is_stream = true;
    JoinFinished();
    threads_.emplace_back([this] { Work(); });
    return true;
  }

 private:
  struct Job {
    std::function<void()> fn;
    Clock::time_point queued_at;
  };

  void Work() {
    tl_pool = this;
    for (;;) {
      Job job;
      {
        std::unique_lock<std::mutex> lock(mu_);
        cv_.wait(lock, [this] { return stopping_ || !jobs_.empty(); });
        if (jobs_.empty()) return;
        job = std::move(jobs_.front());
        jobs_.pop_front();
      }
      tl_waited = Clock::now() - job.queued_at;
      tl_close_after_response = false;
      job.fn();
      if (tl_is_stream) {
        std::lock_guard<std::mutex> lock(mu_);
        --streams_;
        finished_.push_back(std::this_thread::get_id());
        return;  // its replacement was started by BecomeStream()
      }
    }
  }

  // Streams whose connection ended have returned from Work(); joining them frees their stacks.
  void JoinFinished() {
    for (auto it = threads_.begin(); it != threads_.end();) {
      if (std::find(finished_.begin(), finished_.end(), it->get_id()) != finished_.end()) {
        it->join();
        it = threads_.erase(it);
      } else {
        ++it;
      }
    }
    finished_.clear();
  }

  const ServerLimits limits_;
  HeadReader reader_;
  std::mutex mu_;
  std::condition_variable cv_;
  std::deque<Job> jobs_;
  std::list<std::thread> threads_;
  std::vector<std::thread::id> finished_;
  std::size_t streams_ = 0;
  std::unordered_map<std::string, std::size_t> body_readers_;
  bool stopping_ = false;
};

std::string PeerText(int fd, bool remote, int& port) {
  sockaddr_storage addr{};
  socklen_t len = sizeof addr;
  const int r = remote ? getpeername(fd, reinterpret_cast<sockaddr*>(&addr), &len)
                       : getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  port = 0;
  if (r != 0) return "";
  char host[NI_MAXHOST] = "";
  char serv[NI_MAXSERV] = "";
  if (getnameinfo(reinterpret_cast<sockaddr*>(&addr), len, host, sizeof host, serv, sizeof serv,
                  NI_NUMERICHOST | NI_NUMERICSERV) != 0)
    return "";
  port = std::atoi(serv);
  return host;
}

// A connection as httplib reads and writes it, with the request's deadline on every read:
// a client that sends its request slower than the deadline is cut off however it paces it.
class DeadlineStream final : public httplib::Stream {
 public:
  DeadlineStream(int fd, const ServerLimits& limits, std::string seed)
      : fd_(fd), limits_(limits), seed_(std::move(seed)) {}
  // What was read and not consumed (the start of a pipelined request).
  std::string TakeUnread() {
    std::string rest = seed_.substr(seed_off_);
    rest.append(buf_ + off_, end_ - off_);
    seed_.clear();
    seed_off_ = off_ = end_ = 0;
    return rest;
  }

  void StartRequest() { deadline_ = Clock::now() + limits_.request_deadline; }
  bool deadline_passed() const { return deadline_passed_; }

  bool is_readable() const override { return seed_off_ < seed_.size() || WaitRead() > 0; }
  bool is_writable() const override {
    if (PollOne(fd_, POLLOUT, limits_.io_timeout) <= 0) return false;
    // Alive unless the peer closed: readable with nothing to read.
    if (PollOne(fd_, POLLIN, Clock::duration::zero()) <= 0) return true;
    char b;
    return ::recv(fd_, &b, 1, MSG_PEEK) > 0;
  }
  ssize_t read(char* ptr, size_t size) override {
    if (seed_off_ < seed_.size()) {  // what the head reader read first
      const size_t n = std::min(size, seed_.size() - seed_off_);
      std::memcpy(ptr, seed_.data() + seed_off_, n);
      seed_off_ += n;
      return static_cast<ssize_t>(n);
    }
    if (off_ == end_) {
      if (WaitRead() <= 0) return -1;
      ssize_t n;
      do {
        n = ::recv(fd_, buf_, sizeof buf_, 0);
      } while (n < 0 && errno == EINTR);
      if (n <= 0) return n;
      off_ = 0;
      end_ = static_cast<size_t>(n);
    }
    const size_t n = std::min(size, end_ - off_);
    std::memcpy(ptr, buf_ + off_, n);
    off_ += n;
    return static_cast<ssize_t>(n);
  }
  ssize_t write(const char* ptr, size_t size) override {
    if (PollOne(fd_, POLLOUT, limits_.io_timeout) <= 0) return -1;
    ssize_t n;
    do {
      n = ::send(fd_, ptr, size, MSG_NOSIGNAL);
    } while (n < 0 && errno == EINTR);
    return n;
  }
  void get_remote_ip_and_port(std::string& ip, int& port) const override {
    ip = PeerText(fd_, true, port);
  }
  void get_local_ip_and_port(std::string& ip, int& port) const override {
    ip = PeerText(fd_, false, port);
  }
  ::socket_t socket() const override { return fd_; }

 private:
  // Readable within the I/O timeout and before the request's deadline.
  int WaitRead() const {
    const auto left = deadline_ - Clock::now();
    if (left <= Clock::duration::zero()) {
      deadline_passed_ = true;
      return 0;
    }
    const bool deadline_first = left < limits_.io_timeout;
    const int r = PollOne(fd_, POLLIN, std::min<Clock::duration>(left, limits_.io_timeout));
    if (r == 0 && deadline_first) deadline_passed_ = true;
    return r;
  }

  const int fd_;
  const ServerLimits& limits_;
  Clock::time_point deadline_ = Clock::now();
  mutable bool deadline_passed_ = false;
  std::string seed_;
  size_t seed_off_ = 0;
  char buf_[4096];
  size_t off_ = 0, end_ = 0;
};

// After a refused body: send FIN, then read and drop what the client still sends for a
// moment, so that it can read the response instead of getting a reset.
void LingeringClose(int fd) {
  ::shutdown(fd, SHUT_WR);
  const auto until = Clock::now() + std::chrono::milliseconds(500);
  char sink[16384];
  std::size_t dropped = 0;
  while (Clock::now() < until && dropped < (8u << 20)) {
    if (PollOne(fd, POLLIN, until - Clock::now()) <= 0) break;
    const ssize_t n = ::recv(fd, sink, sizeof sink, 0);
    if (n <= 0) break;
    dropped += static_cast<std::size_t>(n);
  }
  ::close(fd);
}

void RefuseOverloaded(int fd, Clock::duration waited) {
  const auto ms = std::chrono::duration_cast<std::chrono::milliseconds>(waited).count();
  const std::string reply =
      RawErrorResponse(503, "Service Unavailable", "overloaded",
                       "the station waited " + std::to_string(ms) +
                           " ms for a free request worker; the request was not read",
                       true);
  (void)::send(fd, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  ::shutdown(fd, SHUT_RDWR);
  ::close(fd);
}

void RefuseSlowBodies(int fd, const std::string& peer, std::size_t max) {
  const std::string reply =
      RawErrorResponse(503, "Service Unavailable", "overloaded",
                       std::to_string(max) + " request bodies of " + peer +
                           " are being read already; the request was not read",
                       true);
  (void)::send(fd, reply.data(), reply.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
  LingeringClose(fd);
}

}  // namespace

bool BecomeStream() { return tl_pool != nullptr && tl_pool->BecomeStream(); }

void CloseAfterResponse() { tl_close_after_response = true; }

ApiServer::ApiServer(ServerLimits limits) : limits_(limits) {
  new_task_queue = [this] {
    return new ConnectionPool(limits_,
                              [this](HeadReader::Ready ready) { ServeRequest(std::move(ready)); });
  };
  const auto io = static_cast<time_t>(limits_.io_timeout.count());
  set_read_timeout(io, 0);
  set_write_timeout(io, 0);
  // SO_REUSEADDR only: httplib's default also sets SO_REUSEPORT, with which a second station
  // binds the same port and both answer.
  set_socket_options([this](::socket_t sock) {
    int yes = 1;
    ::setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
    listen_fd_ = sock;
  });
}

ApiServer::~ApiServer() { stop(); }

int ApiServer::Bind(const std::string& host, int port, std::string* why) {
  errno = 0;
  int bound = -1;
  if (port == 0) {
    bound = bind_to_any_port(host);
  } else {
    bound = bind_to_port(host, port) ? port : -1;
  }
  if (bound <= 0) {
    if (why) *why = errno ? std::strerror(errno) : "the address does not resolve";
    return -1;
  }
  // httplib listens with a backlog of 5; a second listen() on the socket raises it.
  if (listen_fd_ >= 0) ::listen(listen_fd_, limits_.listen_backlog);
  return bound;
}

bool ApiServer::process_and_close_socket(::socket_t sock) {
  if (tl_admitting == nullptr) {  // not from the pool's enqueue: no reader to take it
    ::close(sock);
    return false;
  }
  tl_admitting->reader().Admit(sock);
  return true;
}

void ApiServer::ServeRequest(HeadReader::Ready ready) {
  const int sock = ready.fd;
  const int served = ready.served;
  if (tl_waited > limits_.max_queue_wait) {
    RefuseOverloaded(sock, tl_waited);
    return;
  }
  // A body still to come holds this worker until it is in: one peer may hold only so many.
  if (ready.body_pending && !tl_pool->TakeBodyReader(ready.peer)) {
    RefuseSlowBodies(sock, ready.peer, limits_.max_body_readers_per_peer);
    return;
  }
  struct Release {
    ConnectionPool* pool;
    const HeadReader::Ready& r;
    ~Release() {
      if (r.body_pending) pool->ReleaseBodyReader(r.peer);
    }
  } release{tl_pool, ready};
  DeadlineStream stream(sock, limits_, std::move(ready.bytes));
  stream.StartRequest();
  bool closed = false;
  const bool last = served + 1 >= limits_.max_requests_per_connection;
  const bool ok = process_request(stream, last, closed, nullptr);
  if (stream.deadline_passed())
    spdlog::warn("http: closed a connection that did not send its request within {} ms",
                 limits_.request_deadline.count());
  if (tl_close_after_response) {
    LingeringClose(sock);
  } else if (!ok || closed || last || tl_is_stream || svr_sock_ == INVALID_SOCKET || !tl_pool) {
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
  } else {
    tl_pool->reader().Admit(sock, stream.TakeUnread(), served + 1);  // kept alive
  }
}

}  // namespace eol::station::http
