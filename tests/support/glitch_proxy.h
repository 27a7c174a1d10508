// Test support: a Modbus TCP proxy on 127.0.0.1 between a client and a real server that
// spoils the next reply to a read when armed: another unit id, another function code, or
// half a frame (the client then times out). It counts the request frames it forwards, so a
// test can tell whether the client retried. One client connection at a time (a client that
// reconnects gets a fresh upstream connection).
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace eol::testing {

class GlitchProxy {
 public:
  enum class Glitch { kNone, kForeignUnit, kWrongFunction, kTruncated };

  explicit GlitchProxy(int upstream_port) : upstream_port_(upstream_port) {
    listen_fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    sockaddr_in a = Loopback(0);
    socklen_t len = sizeof a;
    if (bind(listen_fd_, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0 &&
        listen(listen_fd_, 4) == 0 &&
        getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&a), &len) == 0)
      port_ = ntohs(a.sin_port);
    thread_ = std::thread([this] { Serve(); });
  }
  ~GlitchProxy() {
    stop_ = true;
    thread_.join();
    close(listen_fd_);
  }
  GlitchProxy(const GlitchProxy&) = delete;
  GlitchProxy& operator=(const GlitchProxy&) = delete;

  int port() const { return port_; }  // 0 when it could not listen
  // Spoils the next reply to a read request (function 1..4), once.
  void Arm(Glitch g) { glitch_ = g; }
  bool armed() const { return glitch_.load() != Glitch::kNone; }
  // Request frames forwarded since construction.
  int requests() const { return requests_.load(); }

 private:
  static sockaddr_in Loopback(int port) {
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    a.sin_port = htons(static_cast<std::uint16_t>(port));
    return a;
  }

  void Serve() {
    while (!stop_) {
      pollfd p{listen_fd_, POLLIN, 0};
      if (poll(&p, 1, 20) <= 0) continue;
      const int client = accept4(listen_fd_, nullptr, nullptr, SOCK_CLOEXEC);
      if (client < 0) continue;
      const int upstream = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
      const sockaddr_in a = Loopback(upstream_port_);
      if (connect(upstream, reinterpret_cast<const sockaddr*>(&a), sizeof a) == 0)
        Relay(client, upstream);
      close(upstream);
      close(client);
    }
  }

  // Until either side closes (or the proxy stops).
  void Relay(int client, int upstream) {
    std::vector<std::uint8_t> buf(1024);
    while (!stop_) {
      pollfd p[2] = {{client, POLLIN, 0}, {upstream, POLLIN, 0}};
      if (poll(p, 2, 20) <= 0) continue;
      if (p[0].revents != 0) {
        const ssize_t n = recv(client, buf.data(), buf.size(), 0);
        if (n <= 0) return;
        for (ssize_t i = 0; i + 6 <= n; i += 6 + ((buf[i + 4] << 8) | buf[i + 5])) ++requests_;
        if (send(upstream, buf.data(), static_cast<std::size_t>(n), MSG_NOSIGNAL) != n) return;
      }
      if (p[1].revents != 0) {
        ssize_t n = recv(upstream, buf.data(), buf.size(), 0);
        if (n <= 0) return;
        n = Spoil(buf, n);
        if (n > 0 && send(client, buf.data(), static_cast<std::size_t>(n), MSG_NOSIGNAL) != n)
          return;
      }
    }
  }

  // The reply as sent on: changed, or cut short, when armed and a read is answered.
  ssize_t Spoil(std::vector<std::uint8_t>& reply, ssize_t n) {
    if (n < 9 || reply[7] < 1 || reply[7] > 4) return n;
    switch (glitch_.exchange(Glitch::kNone)) {
      case Glitch::kNone:
        return n;
      case Glitch::kForeignUnit:
        reply[6] = 7;
        return n;
      case Glitch::kWrongFunction:
        reply[7] = reply[7] == 4 ? 3 : 4;  // a well-formed frame of another read
        return n;
      case Glitch::kTruncated:
        return 8;
    }
    return n;
  }

  const int upstream_port_;
  int listen_fd_ = -1;
  int port_ = 0;
  std::atomic<bool> stop_{false};
  std::atomic<Glitch> glitch_{Glitch::kNone};
  std::atomic<int> requests_{0};
  std::thread thread_;  // last: starts after the members it uses exist
};

}  // namespace eol::testing
