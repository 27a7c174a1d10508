// The station's HTTP/JSON API (cpp-httplib), default 127.0.0.1:8080.
//
//   GET  /api/status            live state, current serial, last result, counts
//   GET  /api/events            server-sent events: state changes and verdicts
//   GET  /api/units/{serial}    every test of that serial, newest first (no curves)
//   GET  /api/tests/{id}        one test with its curves
//   GET  /api/tests?from=&to=&verdict=&serial=&limit=   tests in a time range
//   POST /api/tests             {"serial": "..."} starts a test (bearer token when configured)
//   PUT  /api/recipe            a new version of the recipe (engineer token; audited)
//   GET  /api/recipe/audit      who changed the recipe, when, old and new hash
//   GET  /api/recipe            the recipe in use with its hash (limits and masks)
//   GET  /api/stats?from=&to=&recipe_hash=&gauge=&reference=NAME=VALUE&sigma_span=
//                               capability, drift alarms, gauge study (station/stats_report.h)
//   GET  /api/detectability?k_fixture=&limit_sigmas=&required_sigmas=
//                               where each defect class shows with this recipe and fixture
//                               (station/qc_service.h; k_fixture from the gap diagnosis)
//   POST /api/teach             {"serials": [...], "method", "confidence", "coverage"}: limits
//                               learned from those units' latest stored tests; returns the
//                               proposed recipe (version + 1) and the summary; engineer
//                               token; nothing changes until the recipe is PUT
//   GET  /metrics               Prometheus text: tests by outcome, state, last resonance
//   GET  /                      the operator page (station/web)
//
// Errors are JSON {"error": {"code": "...", "message": "..."}} with a fitting HTTP status.
// Reads need no token; request bodies are limited to 64 KiB. Reads of the database go
// through a connection of the API's own that never recovers unfinished tests.
//
// This is a thin transport: one handler per route in station/http/*_routes.cc, sharing
// RequireRole and ParseBody (station/http/request.h); the station decides (RecipeChange,
// TeachResult) and only station/http/ maps its typed results to statuses and JSON.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "station/config.h"
#include "station/recipe.h"
#include "station/recipe_change.h"
#include "station/status_board.h"

namespace httplib {
class Server;
}

namespace eol::station {

namespace http {
struct ApiContext;
}

struct HttpOptions {
  std::string listen = "127.0.0.1";
  int port = 8080;  // 0: any free port (see HttpApi::port())
  std::string db_path;
  // Empty: starting tests needs no token. Recipe changes always need an engineer token.
  std::vector<ApiToken> tokens;
  std::string web_root;  // folder of the operator page; empty: built-in fallback page
};

// What the API asks of the station.
struct HttpHandlers {
  // Queues a test for `serial`; false with the reason when refused (busy, stopping).
  std::function<bool(const std::string& serial, std::string* why)> start_test;
  // The recipe in use as JSON, with its "hash".
  std::function<nlohmann::json()> recipe;
  // The recipe in use, parsed (teaching and detectability work from it).
  std::function<std::shared_ptr<const Recipe>()> current_recipe;
  // Validates, stores and activates a new recipe version (Station::ChangeRecipe).
  std::function<RecipeChange(const nlohmann::json& recipe, const ApiToken& who)> change_recipe;
};

class HttpApi {
 public:
  HttpApi(StatusBoard& board, HttpOptions options, HttpHandlers handlers);
  ~HttpApi();
  HttpApi(const HttpApi&) = delete;
  HttpApi& operator=(const HttpApi&) = delete;

  // Binds and serves in a thread. Throws std::runtime_error naming the address on failure.
  void Start();
  void Stop();
  int port() const { return port_; }

 private:
  std::unique_ptr<http::ApiContext> context_;
  std::unique_ptr<httplib::Server> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace eol::station
