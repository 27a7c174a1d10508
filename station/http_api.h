// The station's HTTP/JSON API (cpp-httplib), default 127.0.0.1:8080.
//
//   GET  /api/status            live state, current serial, last result, counts
//   GET  /api/events            server-sent events: state changes and verdicts
//   GET  /api/units/{serial}    every test of that serial, newest first (no curves)
//   GET  /api/tests/{id}        one test with its curves
//   GET  /api/tests?from=&to=&verdict=&serial=&limit=   tests in a time range
//   POST /api/tests             {"serial": "..."} starts a test (bearer token when configured)
//   GET  /api/recipe            the recipe in use with its hash (limits and masks)
//   GET  /metrics               Prometheus text: tests by outcome, state, last resonance
//   GET  /                      the operator page (station/web)
//
// Errors are JSON {"error": {"code": "...", "message": "..."}} with a fitting HTTP status.
// Reads need no token; request bodies are limited to 64 KiB. Reads of the database go
// through a connection of the API's own that never recovers unfinished tests.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "station/status_board.h"

namespace httplib {
class Server;
}

namespace eol::db {
class Store;
}

namespace eol::station {

struct HttpOptions {
  std::string listen = "127.0.0.1";
  int port = 8080;  // 0: any free port (see HttpApi::port())
  std::string db_path;
  std::string operator_token;  // empty: writes need no token
  std::string engineer_token;
  std::string web_root;  // folder of the operator page; empty: built-in fallback page
  nlohmann::json recipe;  // served at GET /api/recipe: {"id", "version", "hash", "masks", ...}
};

class HttpApi {
 public:
  // Queues a test for `serial`; returns false with the reason when refused (busy, locked).
  using StartTest = std::function<bool(const std::string& serial, std::string* why)>;

  HttpApi(StatusBoard& board, HttpOptions options, StartTest start_test);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  // Binds and serves in a thread. Throws std::runtime_error naming the address on failure.
  void Start();
  void Stop();
  int port() const { return port_; }

 private:
  void Routes();

  StatusBoard& board_;
  HttpOptions options_;
  StartTest start_test_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
  std::mutex db_mu_;
  std::unique_ptr<db::Store> db_;
};

}  // namespace eol::station
