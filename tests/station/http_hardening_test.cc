// The HTTP server's capacity does not depend on long-lived or slow clients (issue 14): event
// streams do not hold request workers, slow requests are cut off at their deadline, a request
// that waited too long for a worker is refused unread, and bodies are bounded however they are
// framed. Real servers on 127.0.0.1, real sockets.
#include <gtest/gtest.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "db/store.h"
#include "station/daemon/http_api.h"
#include "tests/support/child_process.h"
#include "tests/support/raw_client.h"
#include "tests/support/station_ready.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

using eol::testing::RawClient;

// An API on a free port with a real (empty) SQLite store; counts the tests it was asked to
// start.
struct Api {
  explicit Api(ServerLimits limits) : board("http-capacity") {
    db::Store::Open(dir / "s.sqlite");
    HttpOptions o;
    o.port = 0;
    o.db_path = dir / "s.sqlite";
    o.limits = limits;
    HttpHandlers h;
    h.start_test = [this](const TestRequest&, std::string*, VariantRefusal*) {
      ++started;
      return true;
    };
    api = std::make_unique<HttpApi>(board, o, h);
    api->Start();
  }
  ~Api() { api->Stop(); }
  int port() const { return api->port(); }

  eol::testing::TempDir dir;
  StatusBoard board;
  std::atomic<int> started{0};
  std::unique_ptr<HttpApi> api;
};

std::chrono::milliseconds TimeStatus(int port, int* status) {
  httplib::Client c("127.0.0.1", port);
  c.set_connection_timeout(3, 0);
  c.set_read_timeout(3, 0);
  const auto t0 = Clock::now();
  const auto res = c.Get("/api/status");
  *status = res ? res->status : -1;
  return std::chrono::duration_cast<std::chrono::milliseconds>(Clock::now() - t0);
}

TEST(HttpCapacity, StatusAnswersWithMoreStreamsThanWorkersAndSlowClients) {
  ServerLimits limits;
  limits.request_workers = 8;
  Api api(limits);
  std::vector<std::unique_ptr<RawClient>> streams;
  for (int i = 0; i < 16; ++i) {
    streams.push_back(std::make_unique<RawClient>(api.port()));
    ASSERT_TRUE(streams.back()->Send("GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"));
  }
  for (auto& s : streams)
    ASSERT_NE(s->ReadUntil("\r\n\r\n", 5s).find("text/event-stream"), std::string::npos)
        << "a stream was not served: " << s->ReadUntil("\r\n\r\n", 0ms);
  // Slow clients: a request line and no more.
  std::vector<std::unique_ptr<RawClient>> slow;
  for (int i = 0; i < 4; ++i) {
    slow.push_back(std::make_unique<RawClient>(api.port()));
    ASSERT_TRUE(slow.back()->Send("GET /api/status HTTP/1.1\r\n"));
  }
  int status = 0;
  const auto took = TimeStatus(api.port(), &status);
  EXPECT_EQ(status, 200);
  EXPECT_LT(took, 1000ms);
}

TEST(HttpCapacity, StreamsBeyondTheMaximumAre503WithAJsonBody) {
  ServerLimits limits;
  limits.max_streams = 2;
  Api api(limits);
  RawClient a(api.port()), b(api.port()), c(api.port());
  for (RawClient* s : {&a, &b}) {
    ASSERT_TRUE(s->Send("GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"));
    ASSERT_NE(s->ReadUntil("\r\n\r\n", 5s).find("200 OK"), std::string::npos);
  }
  ASSERT_TRUE(c.Send("GET /api/events HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n"));
  const std::string third = c.ReadUntil("}}", 5s);
  EXPECT_NE(third.find("503"), std::string::npos) << third;
  EXPECT_NE(third.find(R"("code":"too_many_streams")"), std::string::npos) << third;
}

TEST(HttpCapacity, ASlowRequestIsCutOffAtItsDeadlineHoweverItIsPaced) {
  ServerLimits limits;
  limits.head_deadline = 1000ms;  // the head, read before a worker is taken
  limits.request_deadline = 1000ms;
  Api api(limits);
  RawClient slow(api.port());
  const std::string request =
      "GET /api/status HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Pad: " + std::string(200, 'a') + "\r\n\r\n";
  // One byte every 50 ms never trips the 5 s read timeout; only the deadline stops it.
  const auto t0 = Clock::now();
  for (char ch : request) {
    if (!slow.Send(std::string(1, ch))) break;
    slow.ReadUntil("\n", 50ms);
    if (slow.closed()) break;
  }
  EXPECT_TRUE(slow.closed()) << "the server still reads a request after "
                             << (Clock::now() - t0) / 1ms << " ms";
  EXPECT_LT(Clock::now() - t0, 3s);
}

TEST(HttpCapacity, APostThatWaitedTooLongForAWorkerIsRefusedUnread) {
  ServerLimits limits;
  limits.request_workers = 1;
  limits.request_deadline = 1500ms;
  limits.max_queue_wait = 500ms;
  Api api(limits);
  // Holds the only worker until its deadline: a head in full (read without a worker), then
  // a chunked body that never comes.
  RawClient hog(api.port());
  ASSERT_TRUE(
      hog.Send("POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
               "Transfer-Encoding: chunked\r\n\r\n"));
  std::this_thread::sleep_for(100ms);  // the hog's connection reaches the worker first
  RawClient post(api.port());
  const std::string body = R"({"serial": "Q-1"})";
  ASSERT_TRUE(
      post.Send("POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
                "Content-Length: " +
                std::to_string(body.size()) + "\r\n\r\n" + body));
  const std::string answer = post.ReadUntil("}}", 5s);
  EXPECT_NE(answer.find("503"), std::string::npos) << answer;
  EXPECT_NE(answer.find("overloaded"), std::string::npos) << answer;
  EXPECT_EQ(api.started, 0) << "a request its client may have given up on started a test";
  int status = 0;
  TimeStatus(api.port(), &status);
  EXPECT_EQ(status, 200) << "the worker is free again";
}

// Every route and every refusal answers JSON {"error": {"code", "message"}}.
std::string Code(const httplib::Result& res) {
  if (!res) return "no answer";
  const auto j = nlohmann::json::parse(res->body, nullptr, false);
  std::string code;
  if (j.is_object() && j.contains("error")) code = j["error"]["code"];
  return std::to_string(res->status) + " " + code;
}

TEST(HttpGate, UnknownRoutesWrongMethodsAndWrongMediaAreRefusedWithJson) {
  Api api(ServerLimits{});
  httplib::Client c("127.0.0.1", api.port());
  EXPECT_EQ(Code(c.Get("/api/nothing")), "404 not_found");
  EXPECT_EQ(Code(c.Delete("/api/tests")), "405 method_not_allowed");
  EXPECT_EQ(c.Delete("/api/tests")->get_header_value("Allow"), "GET, POST");
  EXPECT_EQ(Code(c.Put("/api/status", "{}", "application/json")), "405 method_not_allowed");
  // A cross-site page's no-cors POST is text/plain: refused before any handler.
  EXPECT_EQ(Code(c.Post("/api/tests", R"({"serial": "X-1"})", "text/plain")),
            "415 unsupported_media_type");
  EXPECT_EQ(Code(c.Post("/api/tests", httplib::Headers{{"Origin", "http://evil.example"}},
                        R"({"serial": "X-1"})", "application/json")),
            "403 cross_origin");
  EXPECT_EQ(api.started, 0);
  const std::string own = "http://127.0.0.1:" + std::to_string(api.port());
  EXPECT_EQ(Code(c.Post("/api/tests", httplib::Headers{{"Origin", own}}, R"({"serial": "X-1"})",
                        "application/json; charset=utf-8")),
            "202 ");
  EXPECT_EQ(api.started, 1);
}

TEST(HttpGate, QueryParametersAreParsedWholeOrRefusedByName) {
  Api api(ServerLimits{});
  httplib::Client c("127.0.0.1", api.port());
  EXPECT_EQ(Code(c.Get("/api/tests?limit=1e12")), "400 bad_limit");
  EXPECT_EQ(Code(c.Get("/api/tests?limit=10abc")), "400 bad_limit");
  EXPECT_EQ(Code(c.Get("/api/tests?from=notadate")), "400 bad_from");
  EXPECT_EQ(Code(c.Get("/api/tests?limit=10&from=2026-11-24T10:00:00%2B01:00")), "200 ");
  EXPECT_EQ(Code(c.Get("/api/tests?outcome=MAYBE")), "400 bad_outcome");
  EXPECT_EQ(Code(c.Get("/api/tests?verdict=MAYBE")), "400 bad_verdict");
  EXPECT_EQ(Code(c.Get("/api/tests?outcome=PASS&verdict=PASS")), "400 bad_outcome");
}

// Issue 17: the filter is named "outcome" as in the records; "verdict" still works.
TEST(HttpGate, TestsFilterByOutcomeUnderEitherName) {
  Api api(ServerLimits{});
  {
    auto store = db::Store::Open(api.dir / "s.sqlite");
    for (const auto& [serial, outcome] :
         {std::pair{"F-1", analysis::Outcome::kPass}, std::pair{"F-2", analysis::Outcome::kFail},
          std::pair{"F-3", analysis::Outcome::kPass}}) {
      db::TestRecord r;
      r.serial = serial;
      r.station_id = "s";
      r.recipe_id = "r";
      r.started_at = r.finished_at = "2026-01-01T10:00:00.000Z";
      r.outcome = outcome;
      store->Insert(r);
    }
  }
  httplib::Client c("127.0.0.1", api.port());
  auto serials = [&](const std::string& query) {
    const auto res = c.Get("/api/tests?" + query);
    std::vector<std::string> out;
    if (!res || res->status != 200) {
      ADD_FAILURE() << query << ": " << (res ? res->body : "no answer");
      return out;
    }
    const auto answer = nlohmann::json::parse(res->body);
    for (const auto& t : answer["tests"]) out.push_back(t["serial"]);
    std::sort(out.begin(), out.end());
    return out;
  };
  EXPECT_EQ(serials("outcome=PASS"), (std::vector<std::string>{"F-1", "F-3"}));
  EXPECT_EQ(serials("verdict=PASS"), (std::vector<std::string>{"F-1", "F-3"}));
  EXPECT_EQ(serials("outcome=FAIL"), (std::vector<std::string>{"F-2"}));
  EXPECT_EQ(serials(""), (std::vector<std::string>{"F-1", "F-2", "F-3"}));
}

TEST(HttpGate, AChunkedBodyAboveTheCapIsRefusedWithoutBuffering) {
  Api api(ServerLimits{});
  RawClient c(api.port());
  ASSERT_TRUE(
      c.Send("POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
             "Transfer-Encoding: chunked\r\n\r\n"));
  const std::string chunk = "4000\r\n" + std::string(0x4000, ' ') + "\r\n";
  for (int i = 0; i < 8 && c.Send(chunk); ++i) {
  }
  const std::string answer = c.ReadUntil("}}", 5s);
  EXPECT_NE(answer.find("413"), std::string::npos) << answer;
  EXPECT_NE(answer.find("too_large"), std::string::npos) << answer;
  EXPECT_EQ(api.started, 0);
}

// A station directory with the shipped recipe and simulated drivers; `http` as given.
void WriteStation(const eol::testing::TempDir& dir, const nlohmann::json& http) {
  std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                             dir / "pmsm-10pole.json");
  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "hardening"},
      {"recipe", "pmsm-10pole.json"},
      {"db", "s.sqlite"},
      {"http", http},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}}.dump();
}

TEST(HttpConfig, ListeningBeyondLoopbackWithoutTokensIsRefusedAtStartup) {
  eol::testing::TempDir dir;
  WriteStation(dir, {{"listen", "0.0.0.0"}, {"port", 0}});
  eol::testing::ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
  const auto code = station.Wait(30s);
  ASSERT_TRUE(code.has_value()) << "the station started: " << station.output();
  EXPECT_NE(*code, 0);
  EXPECT_NE(station.output().find("/http/listen: \"0.0.0.0\" listens beyond this host, which "
                                  "needs \"tokens\""),
            std::string::npos)
      << station.output();
  EXPECT_FALSE(std::filesystem::exists(dir / "s.sqlite")) << "the database was created anyway";
}

// The daemon itself: 50 MB of chunked body leaves its peak memory where it was.
long PeakRssKb(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stol(line.substr(6));
  return -1;
}

TEST(HttpGate, TheDaemonsPeakMemoryStaysFlatUnder50MbOfChunkedBody) {
  eol::testing::TempDir dir;
  std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                             dir / "pmsm-10pole.json");
  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "rss"},
      {"recipe", "pmsm-10pole.json"},
      {"db", "s.sqlite"},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}}.dump();
  eol::testing::ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json"});
  ASSERT_TRUE(station.WaitFor(
      [](const std::string& o) { return eol::testing::PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  const int port = eol::testing::PortFromReadyLine(station.output());
  const long before_kb = PeakRssKb(station.pid());
  RawClient c(port);
  ASSERT_TRUE(
      c.Send("POST /api/tests HTTP/1.1\r\nHost: 127.0.0.1\r\nContent-Type: application/json\r\n"
             "Transfer-Encoding: chunked\r\n\r\n"));
  std::string answer;
  std::thread reader([&] { answer = c.ReadUntil("}}", 20s); });
  const std::string chunk = "10000\r\n" + std::string(0x10000, 'x') + "\r\n";
  std::size_t sent = 0;
  while (sent < (50u << 20) && c.Send(chunk)) sent += 0x10000;
  reader.join();
  const long after_kb = PeakRssKb(station.pid());
  EXPECT_NE(answer.find("413"), std::string::npos) << answer;
  EXPECT_LT(after_kb - before_kb, 16 * 1024)
      << "peak RSS " << before_kb << " kB -> " << after_kb << " kB after " << sent << " bytes";
}

// One station per database and per port: the second exits non-zero naming the cause, and
// the first keeps answering.
TEST(OneStation, ASecondStationOnTheSameDatabaseOrPortExitsNonZero) {
  eol::testing::TempDir dir;
  WriteStation(dir, {{"listen", "127.0.0.1"}, {"port", 0}});
  eol::testing::ChildProcess first({EOL_BINARY, "station", "--config", dir / "station.json"});
  ASSERT_TRUE(first.WaitFor(
      [](const std::string& o) { return eol::testing::PortFromReadyLine(o) > 0; }, 30s))
      << first.output();
  const int port = eol::testing::PortFromReadyLine(first.output());

  eol::testing::ChildProcess same_db({EOL_BINARY, "station", "--config", dir / "station.json"});
  auto code = same_db.Wait(30s);
  ASSERT_TRUE(code.has_value()) << "a second station started on the same database";
  EXPECT_NE(*code, 0);
  EXPECT_NE(same_db.output().find("another station holds"), std::string::npos) << same_db.output();

  eol::testing::TempDir other;
  WriteStation(other, {{"listen", "127.0.0.1"}, {"port", port}});
  eol::testing::ChildProcess same_port({EOL_BINARY, "station", "--config", other / "station.json"});
  code = same_port.Wait(30s);
  ASSERT_TRUE(code.has_value()) << "a second station started on port " << port;
  EXPECT_NE(*code, 0);
  EXPECT_NE(same_port.output().find("cannot listen on 127.0.0.1:" + std::to_string(port) +
                                    ": Address already in use"),
            std::string::npos)
      << same_port.output();

  int status = 0;
  TimeStatus(port, &status);
  EXPECT_EQ(status, 200) << "the first station stopped answering";
}

TEST(HttpServer, ASecondServerOnTheSamePortFailsToBindAndSaysWhy) {
  Api first(ServerLimits{});
  eol::testing::TempDir dir;
  db::Store::Open(dir / "s.sqlite");
  StatusBoard board("second");
  HttpOptions o;
  o.port = first.port();
  o.db_path = dir / "s.sqlite";
  HttpApi second(board, o, HttpHandlers{});
  try {
    second.Start();
    FAIL() << "a second server bound port " << o.port;
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("Address already in use"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace eol::station::http
