#include "station/http_api.h"

#include <httplib.h>
#include <spdlog/spdlog.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "db/store.h"
#include "station/qc_service.h"
#include "station/serial_number.h"
#include "station/stats_report.h"

namespace eol::station {
namespace {

constexpr std::size_t kMaxBody = 64 * 1024;

void SendJson(httplib::Response& res, int status, const nlohmann::json& body) {
  res.status = status;
  res.set_content(body.dump(), "application/json");
}

void SendError(httplib::Response& res, int status, const std::string& code,
               const std::string& message) {
  SendJson(res, status, {{"error", {{"code", code}, {"message", message}}}});
}

std::string BearerToken(const httplib::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  const std::string prefix = "Bearer ";
  return auth.rfind(prefix, 0) == 0 ? auth.substr(prefix.size()) : "";
}

// The configured token presented as "Authorization: Bearer <token>", if any.
const ApiToken* FindToken(const std::vector<ApiToken>& tokens, const httplib::Request& req) {
  const std::string presented = BearerToken(req);
  if (presented.empty()) return nullptr;
  for (const ApiToken& t : tokens)
    if (t.token == presented) return &t;
  return nullptr;
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

}  // namespace

HttpApi::HttpApi(StatusBoard& board, HttpOptions options, HttpHandlers handlers)
    : board_(board), options_(std::move(options)), handlers_(std::move(handlers)) {}

HttpApi::~HttpApi() { Stop(); }

void HttpApi::Start() {
  db_ = db::Store::Open(options_.db_path, db::Store::Role::kReader);
  server_ = std::make_unique<httplib::Server>();
  server_->set_payload_max_length(kMaxBody);
  server_->set_read_timeout(5, 0);
  server_->set_write_timeout(5, 0);
  Routes();
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.listen.c_str());
  } else {
    port_ = server_->bind_to_port(options_.listen.c_str(), options_.port) ? options_.port : -1;
  }
  if (port_ <= 0)
    throw std::runtime_error("http: cannot listen on " + options_.listen + ":" +
                             std::to_string(options_.port) + " (address in use or not local)");
  thread_ = std::thread([this] { server_->listen_after_bind(); });
  spdlog::info("http: serving on http://{}:{}/", options_.listen, port_);
}

void HttpApi::Stop() {
  if (server_) server_->stop();
  if (thread_.joinable()) thread_.join();
}

void HttpApi::Routes() {
  httplib::Server& s = *server_;

  s.Get("/api/status", [this](const httplib::Request&, httplib::Response& res) {
    SendJson(res, 200, board_.Snapshot());
  });

  s.Get("/api/recipe", [this](const httplib::Request&, httplib::Response& res) {
    SendJson(res, 200, handlers_.recipe());
  });

  s.Put("/api/recipe", [this](const httplib::Request& req, httplib::Response& res) {
    const ApiToken* who = FindToken(options_.tokens, req);
    if (!who) return SendError(res, 401, "unauthorized", "an engineer's bearer token is required");
    if (who->role != "engineer")
      return SendError(res, 403, "forbidden", "only engineers may change recipes");
    nlohmann::json body;
    try {
      body = nlohmann::json::parse(req.body);
    } catch (const std::exception&) {
      return SendError(res, 400, "bad_json", "request body is not JSON");
    }
    const auto [status, answer] = handlers_.change_recipe(body, *who);
    SendJson(res, status, answer);
  });

  s.Get("/api/recipe/audit", [this](const httplib::Request&, httplib::Response& res) {
    std::vector<db::RecipeAudit> log;
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      log = db_->AuditLog(100);
    }
    nlohmann::json list = nlohmann::json::array();
    for (const auto& a : log)
      list.push_back(
          {{"at", a.at},
           {"who", a.who},
           {"role", a.role},
           {"recipe_id", a.recipe_id},
           {"old_version", a.old_version ? nlohmann::json(*a.old_version) : nlohmann::json()},
           {"new_version", a.new_version},
           {"old_hash", a.old_hash},
           {"new_hash", a.new_hash},
           {"path", a.path}});
    SendJson(res, 200, {{"audit", list}});
  });

  s.Get("/metrics", [this](const httplib::Request&, httplib::Response& res) {
    const nlohmann::json st = board_.Snapshot();
    std::ostringstream m;
    m << "# HELP eol_tests_total Finished tests since the station started, by outcome.\n"
      << "# TYPE eol_tests_total counter\n";
    for (const char* o : {"pass", "fail", "error", "aborted"})
      m << "eol_tests_total{outcome=\"" << o << "\"} " << st["counts"][o].get<std::uint64_t>()
        << "\n";
    m << "# HELP eol_testing 1 while a test is in progress.\n# TYPE eol_testing gauge\n"
      << "eol_testing " << (st["state"] == "wait_serial" || st["state"] == "idle" ? 0 : 1) << "\n";
    if (st["last"].is_object()) {
      for (const auto& meas : st["last"]["measurements"]) {
        if (meas["name"] != "resonance_f_hz" || !meas["value"].is_number()) continue;
        m << "# HELP eol_last_resonance_hz Resonance of the last tested unit.\n"
          << "# TYPE eol_last_resonance_hz gauge\n"
          << "eol_last_resonance_hz " << meas["value"].get<double>() << "\n";
      }
    }
    res.set_content(m.str(), "text/plain; version=0.0.4");
  });

  s.Get(R"(/api/units/([^/]+))", [this](const httplib::Request& req, httplib::Response& res) {
    const std::string serial = req.matches[1];
    std::string why;
    if (!ValidSerial(serial, &why)) return SendError(res, 400, "bad_serial", why);
    std::vector<db::TestRecord> tests;
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      tests = db_->TestsOfSerial(serial, false);
    }
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : tests) list.push_back(t);
    SendJson(res, 200, {{"serial", serial}, {"tests", list}});
  });

  s.Get(R"(/api/tests/(\d+))", [this](const httplib::Request& req, httplib::Response& res) {
    std::int64_t id = 0;
    try {
      id = std::stoll(req.matches[1]);
    } catch (const std::exception&) {
      return SendError(res, 400, "bad_id", "test id is not a number");
    }
    std::optional<db::TestRecord> t;
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      t = db_->Test(id, true);
    }
    if (!t)
      return SendError(res, 404, "not_found", "no finished test with id " + std::to_string(id));
    SendJson(res, 200, *t);
  });

  s.Get("/api/tests", [this](const httplib::Request& req, httplib::Response& res) {
    db::TestQuery q;
    if (req.has_param("from")) q.from = req.get_param_value("from");
    if (req.has_param("to")) q.to = req.get_param_value("to");
    if (req.has_param("serial")) q.serial = req.get_param_value("serial");
    if (req.has_param("verdict")) {
      q.outcome = analysis::ParseOutcome(req.get_param_value("verdict"));
      if (!q.outcome)
        return SendError(res, 400, "bad_verdict", "verdict must be PASS, FAIL, ERROR or ABORTED");
    }
    if (req.has_param("limit")) {
      try {
        q.limit = std::stoi(req.get_param_value("limit"));
      } catch (const std::exception&) {
        return SendError(res, 400, "bad_limit", "limit must be a whole number");
      }
      if (q.limit < 1 || q.limit > 10000)
        return SendError(res, 400, "bad_limit", "limit must be in [1, 10000]");
    }
    std::vector<db::TestRecord> tests;
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      tests = db_->Tests(q);
    }
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : tests) list.push_back(t);
    SendJson(res, 200, {{"tests", list}});
  });

  s.Get("/api/stats", [this](const httplib::Request& req, httplib::Response& res) {
    StatsRequest q;
    if (req.has_param("from")) q.from = req.get_param_value("from");
    if (req.has_param("to")) q.to = req.get_param_value("to");
    if (req.has_param("recipe_hash")) q.recipe_hash = req.get_param_value("recipe_hash");
    if (req.has_param("gauge")) q.gauge_serial = req.get_param_value("gauge");
    std::string why;
    for (std::size_t i = 0; i < req.get_param_value_count("reference"); ++i)
      if (!ParseReference(req.get_param_value("reference", i), q.reference, &why))
        return SendError(res, 400, "bad_reference", why);
    if (req.has_param("sigma_span")) {
      const std::string v = req.get_param_value("sigma_span");
      if (v != "4" && v != "6")
        return SendError(res, 400, "bad_sigma_span", "sigma_span must be 4 or 6");
      q.gauge.sigma_span = std::stod(v);
    }
    if (const std::string bad = ValidateStatsRequest(q); !bad.empty())
      return SendError(res, 400, "bad_request", bad);
    nlohmann::json report;
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      report = StatsReport(*db_, q);
    }
    SendJson(res, 200, report);
  });

  s.Get("/api/detectability", [this](const httplib::Request& req, httplib::Response& res) {
    double k_fixture = 0.0, limit_sigmas = 3.0, required_sigmas = 3.0;
    for (auto [name, target] : {std::pair<const char*, double*>{"k_fixture", &k_fixture},
                                {"limit_sigmas", &limit_sigmas},
                                {"required_sigmas", &required_sigmas}}) {
      if (!req.has_param(name)) continue;
      const std::string v = req.get_param_value(name);
      char* end = nullptr;
      const double x = std::strtod(v.c_str(), &end);
      if (v.empty() || *end != '\0' || !(x > 0.0) || !std::isfinite(x))
        return SendError(res, 400, "bad_parameter",
                         std::string(name) + " must be a positive number, got '" + v + "'");
      *target = x;
    }
    const auto recipe = handlers_.current_recipe();
    const analysis::DetectabilitySummary summary = analysis::PredictDetectability(
        DetectabilityOptionsFor(*recipe, k_fixture, limit_sigmas, required_sigmas));
    const std::string source =
        k_fixture > 0.0 ? "k_fixture parameter" : "the chain's default fixture";
    nlohmann::json body = DetectabilityJson(
        summary, source,
        "the recipe's limits as +-" + nlohmann::json(limit_sigmas).dump() + " sigma",
        required_sigmas);
    body["recipe"] = {{"id", recipe->id}, {"version", recipe->version}, {"hash", recipe->hash}};
    SendJson(res, summary.usable ? 200 : 422, body);
  });

  s.Post("/api/teach", [this](const httplib::Request& req, httplib::Response& res) {
    const ApiToken* who = FindToken(options_.tokens, req);
    if (!who) return SendError(res, 401, "unauthorized", "an engineer's bearer token is required");
    if (who->role != "engineer")
      return SendError(res, 403, "forbidden", "only engineers may teach limits");
    nlohmann::json body;
    try {
      body = nlohmann::json::parse(req.body);
    } catch (const std::exception&) {
      return SendError(res, 400, "bad_json", "request body is not JSON");
    }
    if (!body.is_object() || !body.contains("serials") || !body["serials"].is_array() ||
        body["serials"].empty())
      return SendError(res, 400, "bad_request", "body must be {\"serials\": [\"...\", ...]}");
    analysis::TeachOptions options;
    try {
      options.method = body.value("method", options.method);
      options.confidence = body.value("confidence", options.confidence);
      options.coverage = body.value("coverage", options.coverage);
      options.allow_few_units = body.value("allow_few_units", options.allow_few_units);
    } catch (const std::exception& e) {
      return SendError(res, 400, "bad_request", std::string("options: ") + e.what());
    }
    std::string why;
    if (!options.IsValid(&why)) return SendError(res, 400, "bad_request", "options: " + why);
    std::vector<analysis::GoldenUnit> golden;
    nlohmann::json skipped = nlohmann::json::array();
    {
      std::lock_guard<std::mutex> lock(db_mu_);
      for (const auto& s : body["serials"]) {
        if (!s.is_string() || !ValidSerial(s.get<std::string>(), &why))
          return SendError(res, 400, "bad_serial", "serials: " + s.dump() + ": " + why);
        const std::string serial = s.get<std::string>();
        const auto latest = db_->LatestOfSerial(serial);
        if (!latest || latest->outcome == analysis::Outcome::kError ||
            latest->outcome == analysis::Outcome::kAborted) {
          skipped.push_back(serial + (latest ? ": latest test is " +
                                                   std::string(analysis::ToString(latest->outcome))
                                             : ": no test stored"));
          continue;
        }
        const auto full = db_->Test(latest->id, true);
        if (full) golden.push_back(GoldenFromRecord(*full, serial));
      }
    }
    const auto recipe = handlers_.current_recipe();
    const analysis::TeachSummary summary = analysis::TeachLimits(recipe->limits, golden, options);
    nlohmann::json answer = TeachSummaryJson(summary, options);
    answer["skipped"] = skipped;
    answer["previous"] = {{"id", recipe->id}, {"version", recipe->version}, {"hash", recipe->hash}};
    if (!summary.usable) return SendJson(res, 422, answer);
    const nlohmann::json proposed = TaughtRecipeJson(*recipe, summary, options);
    try {
      const Recipe checked = ParseRecipe(proposed, "taught recipe");
      answer["recipe"] = proposed;
      answer["recipe_hash"] = checked.hash;
    } catch (const std::exception& e) {
      return SendError(res, 422, "invalid_recipe", e.what());
    }
    SendJson(res, 200, answer);
  });

  s.Post("/api/tests", [this](const httplib::Request& req, httplib::Response& res) {
    if (!options_.tokens.empty() && !FindToken(options_.tokens, req))
      return SendError(res, 401, "unauthorized", "a valid bearer token is required");
    nlohmann::json body;
    try {
      body = nlohmann::json::parse(req.body);
    } catch (const std::exception&) {
      return SendError(res, 400, "bad_json", "request body is not JSON");
    }
    if (!body.is_object() || !body.contains("serial") || !body["serial"].is_string())
      return SendError(res, 400, "bad_serial", "body must be {\"serial\": \"...\"}");
    const std::string serial = body["serial"].get<std::string>();
    std::string why;
    if (!ValidSerial(serial, &why)) return SendError(res, 400, "bad_serial", why);
    if (!handlers_.start_test(serial, &why)) return SendError(res, 409, "busy", why);
    SendJson(res, 202, {{"serial", serial}, {"accepted", true}});
  });

  s.Get("/api/events", [this](const httplib::Request&, httplib::Response& res) {
    auto last = std::make_shared<std::uint64_t>(board_.last_event());
    res.set_header("Cache-Control", "no-cache");
    res.set_chunked_content_provider(
        "text/event-stream", [this, last](std::size_t, httplib::DataSink& sink) {
          const auto events = board_.EventsAfter(*last, std::chrono::milliseconds(1000));
          if (events.empty()) {
            const std::string ping = ": keep-alive\n\n";
            return sink.write(ping.data(), ping.size());
          }
          for (const auto& [seq, e] : events) {
            const std::string msg = "id: " + std::to_string(seq) +
                                    "\nevent: " + e.value("type", "message") +
                                    "\ndata: " + e.dump() + "\n\n";
            if (!sink.write(msg.data(), msg.size())) return false;
            *last = seq;
          }
          return true;
        });
  });

  s.Get("/", [this](const httplib::Request&, httplib::Response& res) {
    std::string page;
    if (!options_.web_root.empty()) page = ReadFile(options_.web_root + "/index.html");
    if (page.empty())
      page =
          "<!doctype html><title>EOL station</title><h1>EOL station</h1>"
          "<p>The operator page is not installed; see <a href=\"/api/status\">/api/status</a>.";
    res.set_content(page, "text/html; charset=utf-8");
  });
  if (!options_.web_root.empty()) s.set_mount_point("/static", options_.web_root);

  s.set_exception_handler(
      [](const httplib::Request& req, httplib::Response& res, std::exception_ptr ep) {
        std::string what = "unknown";
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          what = e.what();
        } catch (...) {
        }
        spdlog::error("http: {} {}: {}", req.method, req.path, what);
        SendError(res, 500, "internal", what);
      });
}

}  // namespace eol::station
