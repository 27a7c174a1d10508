// Test support: a crowd of hostile Modbus TCP clients on 127.0.0.1 (idle, slow, malformed,
// connect-and-close) around one well-behaved client, whose answers and their latencies are
// what a server that no client can stall or kill must keep giving. Raw sockets: the frames
// are built here, byte by byte, so the slow and broken ones are exactly what is asked.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <random>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

namespace eol::testing {

using ModbusClock = std::chrono::steady_clock;

// A connected socket to 127.0.0.1:port (-1 when the connection failed).
inline int ConnectModbus(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<std::uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

// A read request (function 3 or 4, `count` registers from `address`) in transaction `tid`.
inline std::vector<std::uint8_t> ReadRequest(std::uint16_t tid, int unit, int function, int address,
                                             int count) {
  return {static_cast<std::uint8_t>(tid >> 8),
          static_cast<std::uint8_t>(tid),
          0,
          0,
          0,
          6,
          static_cast<std::uint8_t>(unit),
          static_cast<std::uint8_t>(function),
          static_cast<std::uint8_t>(address >> 8),
          static_cast<std::uint8_t>(address),
          static_cast<std::uint8_t>(count >> 8),
          static_cast<std::uint8_t>(count)};
}

inline bool SendAll(int fd, const std::vector<std::uint8_t>& bytes) {
  return ::send(fd, bytes.data(), bytes.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(bytes.size());
}

// Reads one MBAP reply within `timeout`; empty when none came (or the server closed).
inline std::vector<std::uint8_t> ReadReply(int fd, std::chrono::milliseconds timeout) {
  std::vector<std::uint8_t> got;
  const auto end = ModbusClock::now() + timeout;
  std::size_t want = 7;
  while (got.size() < want) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(end - ModbusClock::now()).count();
    pollfd p{fd, POLLIN, 0};
    if (left <= 0 || ::poll(&p, 1, static_cast<int>(left)) <= 0) return {};
    std::uint8_t buf[260];
    const ssize_t n = ::recv(fd, buf, want - got.size(), 0);
    if (n <= 0) return {};
    got.insert(got.end(), buf, buf + n);
    if (got.size() >= 7) want = 6 + ((got[4] << 8) | got[5]);
  }
  return got;
}

// True when the server closed the connection within `timeout` (reading and dropping replies).
inline bool ClosedByServer(int fd, std::chrono::milliseconds timeout) {
  const auto end = ModbusClock::now() + timeout;
  for (;;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(end - ModbusClock::now()).count();
    pollfd p{fd, POLLIN, 0};
    if (left <= 0 || ::poll(&p, 1, static_cast<int>(left)) <= 0) return false;
    char buf[512];
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) return true;
  }
}

struct CrowdPlan {
  int port = 0;
  int unit = 1;
  int function = 3;  // of the well-behaved client's reads (3 or 4)
  int address = 0;
  int idle = 8;             // connections that never send a byte
  int slow = 2;             // each sends one valid request a byte every 100-400 ms
  int malformed = 2;        // threads sending garbage or a bad length, reconnecting
  int churn = 1;            // threads connecting and closing at once
  int good_requests = 100;  // the well-behaved client's, one after the other
};

struct CrowdFigures {
  int good_answered = 0;
  double good_max_ms = 0;
  double good_p99_ms = 0;
  int slow_answered = 0;
  int idle_connected = 0;
  int malformed_sent = 0;
  int churned = 0;
};

inline void DribbleOneRequest(int port, int unit, int function, int address, unsigned seed,
                              std::atomic<int>* answered) {
  const int fd = ConnectModbus(port);
  if (fd < 0) return;
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> pause_ms(100, 400);
  for (std::uint8_t b : ReadRequest(7, unit, function, address, 1)) {
    if (!SendAll(fd, {b})) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(pause_ms(rng)));
  }
  const auto reply = ReadReply(fd, std::chrono::milliseconds(2000));
  if (reply.size() >= 8 && reply[7] == function) ++*answered;
  ::close(fd);
}

// Garbage (an HTTP request: protocol id 0x4554), a length of 0, a length of 300, in turn.
inline void SendMalformed(int port, const std::atomic<bool>* stop, std::atomic<int>* sent) {
  const std::vector<std::vector<std::uint8_t>> frames = {
      {'G', 'E', 'T', ' ', '/', ' ', 'H', 'T', 'T', 'P', '/', '1', '.', '1', '\r', '\n'},
      {0, 1, 0, 0, 0, 0, 1, 3},
      {0, 2, 0, 0, 0x01, 0x2C, 1, 3, 0, 0}};
  for (std::size_t i = 0; !stop->load(); ++i) {
    const int fd = ConnectModbus(port);
    if (fd < 0) continue;
    if (SendAll(fd, frames[i % frames.size()])) ++*sent;
    ClosedByServer(fd, std::chrono::milliseconds(500));
    ::close(fd);
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
}

inline CrowdFigures RunCrowd(const CrowdPlan& plan) {
  CrowdFigures f;
  std::vector<int> idle;
  for (int i = 0; i < plan.idle; ++i)
    if (const int fd = ConnectModbus(plan.port); fd >= 0) idle.push_back(fd);
  f.idle_connected = static_cast<int>(idle.size());
  std::atomic<bool> stop{false};
  std::atomic<int> slow_answered{0}, malformed_sent{0}, churned{0};
  std::vector<std::thread> crowd;
  for (int i = 0; i < plan.slow; ++i)
    crowd.emplace_back(DribbleOneRequest, plan.port, plan.unit, plan.function, plan.address,
                       100u + static_cast<unsigned>(i), &slow_answered);
  for (int i = 0; i < plan.malformed; ++i)
    crowd.emplace_back(SendMalformed, plan.port, &stop, &malformed_sent);
  for (int i = 0; i < plan.churn; ++i)
    crowd.emplace_back([&] {
      while (!stop.load()) {
        if (const int fd = ConnectModbus(plan.port); fd >= 0) {
          ::close(fd);
          ++churned;
        }
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));  // the crowd is in
  std::vector<double> ms;
  const int good = ConnectModbus(plan.port);
  for (int i = 0; good >= 0 && i < plan.good_requests; ++i) {
    const auto t0 = ModbusClock::now();
    const auto tid = static_cast<std::uint16_t>(1000 + i);
    if (!SendAll(good, ReadRequest(tid, plan.unit, plan.function, plan.address, 1))) break;
    const auto reply = ReadReply(good, std::chrono::milliseconds(2000));
    ms.push_back(std::chrono::duration<double, std::milli>(ModbusClock::now() - t0).count());
    if (reply.size() >= 8 && ((reply[0] << 8) | reply[1]) == tid && reply[7] == plan.function)
      ++f.good_answered;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  if (good >= 0) ::close(good);
  stop = true;  // the slow ones send their request to its end
  for (auto& t : crowd) t.join();
  for (int fd : idle) ::close(fd);
  std::sort(ms.begin(), ms.end());
  if (!ms.empty()) {
    f.good_max_ms = ms.back();
    f.good_p99_ms = ms[std::min(ms.size() - 1, ms.size() * 99 / 100)];
  }
  f.slow_answered = slow_answered;
  f.malformed_sent = malformed_sent;
  f.churned = churned;
  return f;
}

// One line of what a crowd run did, for the test's log.
inline std::string Describe(const CrowdPlan& plan, const CrowdFigures& f) {
  std::ostringstream o;
  o << f.idle_connected << " idle, " << plan.slow << " slow (" << f.slow_answered << " answered), "
    << f.malformed_sent << " malformed frames, " << f.churned << " connect-and-close; good client "
    << f.good_answered << " of " << plan.good_requests << " answered, p99 " << f.good_p99_ms
    << " ms, max " << f.good_max_ms << " ms";
  return o.str();
}

}  // namespace eol::testing
