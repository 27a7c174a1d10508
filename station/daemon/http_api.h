// The station's HTTP/JSON API (cpp-httplib), default 127.0.0.1:8080.
//
//   GET  /api/status            live state, current serial, last result, counts, readiness
//                               (ready, not_ready_code, not_ready_text, not_ready_reason,
//                               not_ready: station/daemon/status_board.h, station/daemon/health.h)
//   GET  /api/events            server-sent events: state changes, verdicts, readiness,
//                               messages; a "ping" after 0.5 s without one
//   GET  /api/units/{serial}    every test of that serial, newest first (no curves)
//   GET  /api/tests/{id}        one test with its curves
//   GET  /api/tests?from=&to=&outcome=&serial=&limit=   tests in a time range ("verdict=",
//                               the older name of outcome=, is still accepted)
//   POST /api/tests             {"serial": "...", "operator_id", "shift", "order_number",
//                               "variant"} starts a test (bearer token when configured; the
//                               optional fields as station/daemon/test_request.h accepts them;
//                               "variant" the operator's choice, station/daemon/variants.h: refused
//                               400 unknown_variant, 400 no_variant, 409 variant_conflict)
//   GET  /api/variants          the station's variants with their recipes (id, version, hash)
//                               and the last unit's ("current"); [] with one recipe
//   PUT  /api/recipe            a new version of the recipe (engineer token; audited)
//   GET  /api/recipe/audit      who changed the recipe, when, old and new hash
//   POST /api/recipe/approve    approve a taught proposal and install it (engineer; audited)
//   GET  /api/recipe            the recipe in use with its hash (limits and masks) and its
//                               operator "instructions" with their defaults written out
//   GET  /api/stats?from=&to=&recipe_hash=&population=&subgroup=&gauge=&reference=NAME=VALUE
//        &sigma_span=           capability (Cp/Cpk within, Pp/Ppk overall), run-rule and drift
//                               alarms, gauge study (station/reports/stats_report.h)
//   GET  /api/charts/<measurement>.svg?chart=imr|xbar_r|histogram&from=&to=&last=&subgroup=
//        &population=pass|all&recipe_hash=
//                               a control chart or histogram as image/svg+xml
//                               (station/reports/spc_charts.h); 404 "unknown_measurement",
//                               "no_units"
//   GET  /api/detectability?k_fixture=&limit_sigmas=&required_sigmas=
//                               where each defect class shows with this recipe and fixture
//                               (station/daemon/qc_service.h; k_fixture from the gap diagnosis)
//   POST /api/teach             {"serials": [...], "method", "confidence", "coverage"}: limits
//                               learned from those units' latest stored tests; returns the
//                               proposed recipe (version + 1) and the summary; engineer
//                               token; nothing changes until the recipe is PUT
//   POST /api/pod.svg           {"hits_csv": "<text>", ...}: the POD figure of `eol pod`
//   POST /api/gap.svg           {"simulation": {"name", "text"}, "measured": [...], ...}: the
//                               plot of `eol gap` (both station/daemon/http/figure_routes.cc;
//                               engineer token when tokens are configured)
//   GET  /api/units/{serial}/teardown   the serial's teardown findings, oldest first, each
//                               with who, when and the verdict it judged; "current": the newest
//   POST /api/units/{serial}/teardown   {"found": "defective" | "not-defective", "note"}: an
//                               engineer records a finding under the token's name (201;
//                               append-only, a correction is a new finding; 404
//                               "unknown_serial" for a serial this store never tested)
//   GET  /api/teardown/review?confidence=   hits, misses, false rejects of the current
//                               findings and the share caught (station/reports/teardown_review.h)
//   GET  /api/units/{serial}/report.pdf?test_id=   the unit's printable report as
//                               application/pdf (station/reports/unit_report.h); masks drawn when
//                               the recipe in use is the test's
//   GET  /metrics               Prometheus text: tests by outcome, state, last resonance
//   GET  /                      the operator page (station/web)
//   GET  /engineer              the engineer page (station/web/engineer.html)
//
// Errors are JSON {"error": {"code": "...", "message": "..."}} with a fitting HTTP status.
// Reads need no token; request bodies are limited to 64 KiB (4 MiB for the figure uploads). Reads
// of the database go through a connection of the API's own that never recovers unfinished tests.
//
// This is a thin transport: one handler per route in station/daemon/http/*_routes.cc, sharing
// RequireRole and ParseBody (station/daemon/http/request.h); the station decides (RecipeChange,
// TeachResult) and only station/daemon/http/ maps its typed results to statuses and JSON.
#pragma once

#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#include "station/daemon/config.h"
#include "station/daemon/http/limits.h"
#include "station/daemon/recipe.h"
#include "station/daemon/recipe_change.h"
#include "station/daemon/status_board.h"
#include "station/daemon/test_request.h"

namespace eol::station {

namespace http {
struct ApiContext;
class ApiServer;
}  // namespace http

struct HttpOptions {
  std::string listen = "127.0.0.1";
  int port = 8080;  // 0: any free port (see HttpApi::port())
  std::string db_path;
  // Empty: starting tests needs no token. Recipe changes always need an engineer token.
  std::vector<ApiToken> tokens;
  // Host header names answered besides `listen`, the address connected to and loopback names
  // (station/daemon/http/gate.h); others are refused 421.
  std::vector<std::string> hosts;
  std::string web_root;         // folder of the operator page; empty: built-in fallback page
  std::string language = "en";  // the operator page's language (GET /api/status "language")
  // The central record's URI (station/daemon/central/): GET /api/units/{serial}?scope=plant reads
  // it; empty: that scope answers 400.
  std::string central_postgres;
  http::ServerLimits limits;  // workers, streams, deadlines (station/daemon/http/server.h)
};

// What the API asks of the station.
struct HttpHandlers {
  // Queues a test; false with the reason when refused (busy, stopping, or its variant:
  // then `variant` says how).
  std::function<bool(const TestRequest& request, std::string* why, VariantRefusal* variant)>
      start_test;
  // GET /api/variants (Station::VariantsJson); unset: {"variants": []}.
  std::function<nlohmann::json()> variants;
  // The recipe in use as JSON, with its "hash".
  std::function<nlohmann::json()> recipe;
  // The recipe in use, parsed (teaching and detectability work from it).
  std::function<std::shared_ptr<const Recipe>()> current_recipe;
  // Validates, stores and activates a new recipe version (Station::ChangeRecipe).
  std::function<RecipeChange(const nlohmann::json& recipe, const ApiToken& who)> change_recipe;
  // GET /metrics: the Prometheus exposition text (station/daemon/station_metrics.h).
  std::function<std::string()> metrics;
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
  std::unique_ptr<http::ApiServer> server_;
  std::thread thread_;
  int port_ = 0;
};

}  // namespace eol::station
