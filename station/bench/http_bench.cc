#include "station/bench/http_bench.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>
#include <vector>

#include "db/store.h"
#include "station/daemon/http_api.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station {
namespace {

using Clock = std::chrono::steady_clock;

int Connect(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
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

bool SendAll(int fd, const std::string& s) {
  std::size_t off = 0;
  while (off < s.size()) {
    const ssize_t n = ::send(fd, s.data() + off, s.size() - off, MSG_NOSIGNAL);
    if (n <= 0) return false;
    off += static_cast<std::size_t>(n);
  }
  return true;
}

// The status code of the response on `fd`, reading for at most `wait`; 0 if none.
int ReadStatus(int fd, std::chrono::milliseconds wait) {
  std::string got;
  const auto until = Clock::now() + wait;
  while (got.size() < 12 && Clock::now() < until) {
    pollfd p{fd, POLLIN, 0};
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
    if (::poll(&p, 1, static_cast<int>(std::max<long long>(left.count(), 0))) <= 0) break;
    char buf[512];
    const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
    if (n <= 0) break;
    got.append(buf, static_cast<std::size_t>(n));
  }
  if (got.size() < 12 || got.rfind("HTTP/1.1 ", 0) != 0) return 0;
  return std::atoi(got.substr(9, 3).c_str());
}

// A line of /proc/self/status ("VmRSS", "VmHWM") in MiB.
double ProcStatusMib(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1)) / 1024.0;
  }
  return 0;
}

double Percentile(std::vector<double>& sorted, double p) {
  if (sorted.empty()) return 0;
  const auto i = static_cast<std::size_t>(p * static_cast<double>(sorted.size() - 1) + 0.5);
  return sorted[std::min(i, sorted.size() - 1)];
}

// One client offering `bytes` of chunked body; how far it got and what the server answered.
void OfferChunkedBody(int port, std::size_t bytes, HttpBenchResult* r) {
  const int fd = Connect(port);
  if (fd < 0) return;
  SendAll(fd,
          "POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
          "Transfer-Encoding: chunked\r\n\r\n");
  const std::string chunk = "100000\r\n" + std::string(0x100000, ' ') + "\r\n";
  while (r->chunked_sent_bytes < bytes) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 0) > 0) break;  // the server answered: stop offering
    if (!SendAll(fd, chunk)) break;
    r->chunked_sent_bytes += 0x100000;
  }
  r->chunked_status = ReadStatus(fd, std::chrono::milliseconds(5000));
  ::close(fd);
}

// `n` slow connections until `stop`: each sends a request head one byte every 500 ms and
// reconnects when the server closes it (as an attacker would).
void HoldSlowConnections(int port, int n, const std::atomic<bool>& stop, long* connects) {
  const std::string head =
      "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + std::string(4000, 's') +
      "\r\n\r\n";
  std::vector<int> fds(static_cast<std::size_t>(n), -1);
  std::vector<std::size_t> sent(fds.size(), 0);
  while (!stop) {
    for (std::size_t i = 0; i < fds.size(); ++i) {
      if (fds[i] >= 0) {
        pollfd p{fds[i], POLLIN, 0};
        const bool cut = ::poll(&p, 1, 0) > 0;  // an answer or a close: either ends it
        if (!cut && ::send(fds[i], head.data() + sent[i], 1, MSG_NOSIGNAL) == 1) {
          sent[i] = (sent[i] + 1) % head.size();
          continue;
        }
        ::close(fds[i]);
      }
      fds[i] = Connect(port);
      sent[i] = 0;
      ++*connects;
    }
    for (int k = 0; k < 10 && !stop; ++k)
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  for (const int fd : fds)
    if (fd >= 0) ::close(fd);
}

}  // namespace

HttpBenchResult RunHttpBench(const HttpBenchOptions& o) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("eol-http-bench-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const std::string db_path = (dir / "bench.sqlite").string();
  db::Store::Open(db_path);
  StatusBoard board("http-bench");
  HttpOptions options;
  options.port = 0;
  options.db_path = db_path;
  HttpHandlers handlers;
  handlers.start_test = [](const TestRequest&, std::string* why, VariantRefusal*) {
    *why = "http-bench: tests are not started";
    return false;
  };
  HttpApi api(board, options, handlers);
  api.Start();
  const int port = api.port();
  HttpBenchResult r;

  r.rss_before_mib = ProcStatusMib("VmRSS");
  OfferChunkedBody(port, o.chunked_bytes, &r);
  r.rss_peak_mib = ProcStatusMib("VmHWM");

  r.streams_requested = o.streams;
  std::vector<int> streams;
  for (int i = 0; i < o.streams; ++i) {
    const int fd = Connect(port);
    if (fd < 0) continue;
    SendAll(fd, "GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
    if (ReadStatus(fd, std::chrono::milliseconds(3000)) == 200) ++r.streams_open;
    streams.push_back(fd);
  }

  r.slow_requested = o.slow;
  std::atomic<bool> stop_slow{false};
  std::thread slow([&] { HoldSlowConnections(port, o.slow, stop_slow, &r.slow_connects); });
  std::this_thread::sleep_for(std::chrono::milliseconds(o.slow > 0 ? 1000 : 0));

  std::mutex mu;
  std::vector<double> latencies;
  std::atomic<long> ok{0}, refused{0}, failed{0};
  const auto end = Clock::now() + std::chrono::duration<double>(o.seconds);
  std::vector<std::thread> clients;
  for (int c = 0; c < o.clients; ++c) {
    clients.emplace_back([&] {
      httplib::Client client("127.0.0.1", port);
      client.set_connection_timeout(5, 0);
      client.set_read_timeout(5, 0);
      std::vector<double> mine;
      while (Clock::now() < end) {
        const auto t0 = Clock::now();
        const auto res = client.Get("/api/status");
        const double ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        if (res && res->status == 200) {
          ++ok;
          mine.push_back(ms);
        } else if (res && res->status == 503) {
          ++refused;
        } else {
          ++failed;
        }
      }
      std::lock_guard<std::mutex> lock(mu);
      latencies.insert(latencies.end(), mine.begin(), mine.end());
    });
  }
  for (auto& t : clients) t.join();
  stop_slow = true;
  slow.join();
  for (const int fd : streams) ::close(fd);
  api.Stop();
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);

  r.requests = ok;
  r.refused = refused;
  r.failed = failed;
  std::sort(latencies.begin(), latencies.end());
  r.p50_ms = Percentile(latencies, 0.50);
  r.p90_ms = Percentile(latencies, 0.90);
  r.p99_ms = Percentile(latencies, 0.99);
  r.max_ms = latencies.empty() ? 0 : latencies.back();
  return r;
}

nlohmann::json ToJson(const HttpBenchResult& r) {
  return {{"streams_requested", r.streams_requested},
          {"slow_requested", r.slow_requested},
          {"slow_connects", r.slow_connects},
          {"streams_open", r.streams_open},
          {"status_requests", r.requests},
          {"status_refused_503", r.refused},
          {"status_failed", r.failed},
          {"status_p50_ms", r.p50_ms},
          {"status_p90_ms", r.p90_ms},
          {"status_p99_ms", r.p99_ms},
          {"status_max_ms", r.max_ms},
          {"chunked_status", r.chunked_status},
          {"chunked_sent_bytes", r.chunked_sent_bytes},
          {"rss_before_mib", r.rss_before_mib},
          {"rss_peak_mib", r.rss_peak_mib}};
}

}  // namespace eol::station
