// Issue 34's HTTP findings, against the real server and gate on 127.0.0.1 with a real SQLite
// store: deep JSON is refused before it is parsed or printed, request heads are read before a
// worker is taken (slow clients hold none; oversized heads, too many headers and too many
// waiting connections of one peer are refused with bounded memory), the Host header must
// name this station (DNS rebinding), and no response may be framed.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "db/store.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http_api.h"
#include "tests/support/child_process.h"
#include "tests/support/raw_client.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
using eol::testing::RawClient;

struct Api {
  explicit Api(ServerLimits limits, std::vector<std::string> hosts = {},
               std::string listen = "127.0.0.1")
      : board("http-limits") {
    db::Store::Open(dir / "s.sqlite");
    HttpOptions o;
    o.listen = std::move(listen);
    o.port = 0;
    o.db_path = dir / "s.sqlite";
    o.limits = limits;
    o.hosts = std::move(hosts);
    HttpHandlers h;
    h.start_test = [](const TestRequest&, std::string*, VariantRefusal*) { return true; };
    api = std::make_unique<HttpApi>(board, o, h);
    api->Start();
  }
  ~Api() { api->Stop(); }
  int port() const { return api->port(); }

  eol::testing::TempDir dir;
  StatusBoard board;
  std::unique_ptr<HttpApi> api;
};

// Status and milliseconds of one GET /api/status on a fresh connection.
std::pair<int, double> GetStatus(int port) {
  httplib::Client c("127.0.0.1", port);
  c.set_connection_timeout(3, 0);
  c.set_read_timeout(3, 0);
  const auto t0 = Clock::now();
  const auto res = c.Get("/api/status");
  return {res ? res->status : -1,
          std::chrono::duration<double, std::milli>(Clock::now() - t0).count()};
}

double RssMib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmRSS:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;
  return 0;
}

std::string Post(int port, const std::string& path, const std::string& body) {
  RawClient c(port);
  c.Send("POST " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n" +
         "Content-Length: " + std::to_string(body.size()) + "\r\n\r\n" + body);
  return c.ReadUntil("}}", 10s);
}

TEST(JsonDepth, BracketsAreCountedOutsideStringsOnly) {
  EXPECT_EQ(JsonNestingDepth(R"({"a": [1, {"b": []}]})", 64), 4);
  EXPECT_EQ(JsonNestingDepth(R"({"a": "[[[[{{{{", "b": "\"[["})", 64), 1);
  EXPECT_EQ(JsonNestingDepth("1", 64), 0);
  EXPECT_EQ(JsonNestingDepth(std::string(100000, '['), 64), 65);  // stops at the first too deep
  EXPECT_EQ(Excerpt(nlohmann::json(std::string(1000, 'x'))).size(), 203u);
}

TEST(HttpLimits, DeepJsonIsAnswered400AndTheServerStillServes) {
  Api api(ServerLimits{});
  const std::string deep = std::string(100000, '[') + std::string(100000, ']');
  for (const std::string path : {"/api/pod.svg", "/api/gap.svg", "/api/tests"}) {
    const std::string body = path == "/api/tests"
                                 ? std::string(20000, '[') + std::string(20000, ']')
                                 : R"({"hits": )" + deep + "}";
    const std::string got = Post(api.port(), path, body);
    EXPECT_EQ(got.rfind("HTTP/1.1 400", 0), 0u) << path << ": " << got.substr(0, 300);
    EXPECT_NE(got.find("too_deep"), std::string::npos) << path;
    EXPECT_LT(got.size(), 1000u) << "the rejected value is not printed";
  }
  // 64 levels are still JSON the routes judge (here: a wrong field, named, value cut short).
  const std::string ok_depth = R"({"hits": )" + std::string(63, '[') + std::string(63, ']') + "}";
  const std::string judged = Post(api.port(), "/api/pod.svg", ok_depth);
  EXPECT_EQ(judged.rfind("HTTP/1.1 4", 0), 0u) << judged;
  EXPECT_EQ(judged.find("too_deep"), std::string::npos) << judged;
  EXPECT_EQ(GetStatus(api.port()).first, 200);
}

TEST(HttpLimits, AnOversizedHeadOrTooManyHeadersIs431WithBoundedMemory) {
  Api api(ServerLimits{});
  {
    RawClient c(api.port());
    std::string head = "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n";
    for (int i = 0; i < 65; ++i) head += "X-" + std::to_string(i) + ": a\r\n";
    c.Send(head + "\r\n");
    EXPECT_EQ(c.ReadUntil("}}", 5s).rfind("HTTP/1.1 431", 0), 0u);
  }
  // 100 clients each offering 4 MB of headers: each is cut off at 16 KiB.
  const double before = RssMib();
  std::vector<std::thread> clients;
  std::atomic<int> refused{0};
  for (int i = 0; i < 100; ++i)
    clients.emplace_back([&] {
      RawClient c(api.port());
      c.Send("GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\n");
      const std::string line = "X-Pad: " + std::string(100, 'p') + "\r\n";
      std::string block;
      for (int k = 0; k < 400; ++k) block += line;  // ~43 KB
      for (int k = 0; k < 100 && !c.closed(); ++k) {
        if (!c.Send(block)) break;
        c.ReadUntil("}}", 1ms);
      }
      if (c.ReadUntil("}}", 3s).rfind("HTTP/1.1 431", 0) == 0) ++refused;
    });
  for (auto& t : clients) t.join();
  const double grown = RssMib() - before;
  std::cout << "100 clients offering 4 MB of headers each: " << refused << " answered 431, RSS "
            << before << " -> " << before + grown << " MiB\n";
  EXPECT_GE(refused, 90);  // a few may see a reset instead of the answer
  EXPECT_LT(grown, 50.0);
  EXPECT_EQ(GetStatus(api.port()).first, 200);
}

TEST(HttpLimits, SlowClientsHoldNoWorkerAndANormalRequestIsAnsweredFast) {
  ServerLimits limits;
  limits.request_workers = 4;
  Api api(limits);
  // 64 slow clients (16 per worker): a head a byte at a time, every 100 ms; 16 slow bodies.
  std::atomic<bool> stop{false};
  std::vector<std::thread> slow;
  for (int i = 0; i < 80; ++i)
    slow.emplace_back([&, i] {
      RawClient c(api.port());
      const std::string body = R"({"serial": "SLOW-1"})";
      const std::string req =
          i < 64
              ? "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Pad: " + std::string(200, 'a') +
                    "\r\n\r\n"
              : "POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: "
                "application/json\r\nContent-Length: " +
                    std::to_string(body.size()) + "\r\n\r\n" + body;
      const std::size_t fast = i < 64 ? 0 : req.size() - body.size();  // slow bodies: head at once
      c.Send(req.substr(0, fast));
      for (std::size_t k = fast; k < req.size() && !stop && !c.closed(); ++k) {
        c.Send(req.substr(k, 1));
        c.ReadUntil("\n", 100ms);
      }
    });
  std::this_thread::sleep_for(300ms);
  std::vector<double> ms;
  for (int i = 0; i < 30; ++i) {
    const auto [status, took] = GetStatus(api.port());
    EXPECT_EQ(status, 200);
    ms.push_back(took);
    std::this_thread::sleep_for(30ms);
  }
  stop = true;
  for (auto& t : slow) t.join();
  std::sort(ms.begin(), ms.end());
  std::cout << "80 slow clients on 4 workers: /api/status max " << ms.back() << " ms\n";
  EXPECT_LT(ms.back(), 100.0);
}

TEST(HttpLimits, SlowBodiesOfOnePeerHoldAtMostTheirShareOfWorkers) {
  ServerLimits limits;
  limits.request_workers = 4;
  limits.max_body_readers_per_peer = 2;
  Api api(limits);
  // Chunked bodies are not prefetched: each one read holds a worker until its deadline.
  std::vector<std::unique_ptr<RawClient>> hogs;
  for (int i = 0; i < 4; ++i) {
    hogs.push_back(std::make_unique<RawClient>(api.port()));
    hogs.back()->Send(
        "POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
        "Transfer-Encoding: chunked\r\n\r\n");
  }
  int refused = 0;
  for (auto& h : hogs)
    if (h->ReadUntil("}}", 300ms).find("503") != std::string::npos) ++refused;
  EXPECT_EQ(refused, 2);
  for (int i = 0; i < 10; ++i) {
    const auto [status, took] = GetStatus(api.port());
    EXPECT_EQ(status, 200);
    EXPECT_LT(took, 100.0);
  }
}

TEST(HttpLimits, WaitingConnectionsArePerPeerCappedAndCutAtTheHeadDeadline) {
  ServerLimits limits;
  limits.max_waiting_per_peer = 4;
  limits.head_deadline = 400ms;
  Api api(limits);
  std::vector<std::unique_ptr<RawClient>> idle;
  for (int i = 0; i < 4; ++i) idle.push_back(std::make_unique<RawClient>(api.port()));
  std::this_thread::sleep_for(50ms);
  RawClient fifth(api.port());
  const std::string refused = fifth.ReadUntil("}}", 1s);
  EXPECT_EQ(refused.rfind("HTTP/1.1 503", 0), 0u) << refused;
  EXPECT_NE(refused.find("too many connections from 127.0.0.1"), std::string::npos) << refused;
  const auto t0 = Clock::now();
  for (auto& c : idle) {
    c->ReadUntil("never", 2s);
    EXPECT_TRUE(c->closed());
  }
  EXPECT_LT(Clock::now() - t0, 1500ms);
  EXPECT_EQ(GetStatus(api.port()).first, 200) << "the waiting slots are free again";
}

TEST(HttpLimits, TheHostHeaderMustNameThisStation) {
  Api api(ServerLimits{}, {"eol-1.plant.local"});
  const auto ask = [&](const std::string& host_line) {
    RawClient c(api.port());
    c.Send("GET /api/status HTTP/1.1\r\n" + host_line + "Connection: close\r\n\r\n");
    const std::string got = c.ReadUntil("}}", 3s);
    return got.size() >= 12 ? std::stoi(got.substr(9, 3)) : -1;
  };
  const std::string port = std::to_string(api.port());
  EXPECT_EQ(ask("Host: 127.0.0.1:" + port + "\r\n"), 200);
  EXPECT_EQ(ask("Host: localhost:" + port + "\r\n"), 200);
  EXPECT_EQ(ask("Host: LOCALHOST\r\n"), 200);
  EXPECT_EQ(ask("Host: eol-1.plant.local:" + port + "\r\n"), 200);
  EXPECT_EQ(ask("Host: [::1]:" + port + "\r\n"), 200);
  EXPECT_EQ(ask("Host: evil.example:" + port + "\r\n"), 421);
  EXPECT_EQ(ask("Host: 127.0.0.1.evil.example\r\n"), 421);
  EXPECT_EQ(ask(""), 400);
  EXPECT_EQ(ask("Host: 127.0.0.1\r\nHost: evil.example\r\n"), 400);
}

TEST(HttpLimits, OnEveryInterfaceTheAddressConnectedToIsAHostName) {
  Api api(ServerLimits{}, {}, "0.0.0.0");
  const auto ask = [&](const char* address, const std::string& host) {
    const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
    sockaddr_in a{};
    a.sin_family = AF_INET;
    a.sin_port = htons(static_cast<std::uint16_t>(api.port()));
    inet_pton(AF_INET, address, &a.sin_addr);
    std::string got;
    if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
      const std::string req =
          "GET /api/status HTTP/1.1\r\nHost: " + host + "\r\nConnection: close\r\n\r\n";
      ::send(fd, req.data(), req.size(), MSG_NOSIGNAL);
      char buf[512];
      const ssize_t n = ::recv(fd, buf, sizeof buf, 0);
      if (n > 0) got.assign(buf, static_cast<std::size_t>(n));
    }
    ::close(fd);
    return got.size() >= 12 ? std::stoi(got.substr(9, 3)) : -1;
  };
  EXPECT_EQ(ask("127.0.0.2", "127.0.0.2"), 200);  // the address the client connected to
  EXPECT_EQ(ask("127.0.0.2", "127.0.0.3"), 421);  // another address of this host: not asked
  EXPECT_EQ(ask("127.0.0.2", "0.0.0.0"), 421);
}

TEST(HttpLimits, EveryResponseForbidsFraming) {
  Api api(ServerLimits{});
  httplib::Client c("127.0.0.1", api.port());
  for (const auto& path : {"/api/status", "/api/nothing", "/"}) {
    const auto res = c.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->get_header_value("Content-Security-Policy"), "frame-ancestors 'none'") << path;
    EXPECT_EQ(res->get_header_value("X-Frame-Options"), "DENY") << path;
  }
  RawClient foreign(api.port());
  foreign.Send("GET /api/status HTTP/1.1\r\nHost: evil.example\r\n\r\n");
  EXPECT_NE(foreign.ReadUntil("}}", 3s).find("frame-ancestors 'none'"), std::string::npos);
}

}  // namespace
}  // namespace eol::station::http
