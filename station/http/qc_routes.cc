// Quality engineering: capability and gauge statistics, detectability of defect classes, and
// limits taught from stored good units.
#include <cmath>
#include <cstdlib>

#include "station/http/request.h"
#include "station/http/routes.h"
#include "station/stats_report.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

ApiError BadRequest(std::string code, std::string message) {
  return {ApiErrorKind::kBadRequest, std::move(code), std::move(message)};
}

void GetStats(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  StatsRequest q;
  if (req.has_param("from")) q.from = req.get_param_value("from");
  if (req.has_param("to")) q.to = req.get_param_value("to");
  if (req.has_param("recipe_hash")) q.recipe_hash = req.get_param_value("recipe_hash");
  if (req.has_param("gauge")) q.gauge_serial = req.get_param_value("gauge");
  std::string why;
  for (std::size_t i = 0; i < req.get_param_value_count("reference"); ++i)
    if (!ParseReference(req.get_param_value("reference", i), q.reference, &why))
      return Send(res, BadRequest("bad_reference", why));
  if (req.has_param("sigma_span")) {
    const std::string v = req.get_param_value("sigma_span");
    if (v != "4" && v != "6")
      return Send(res, BadRequest("bad_sigma_span", "sigma_span must be 4 or 6"));
    q.gauge.sigma_span = std::stod(v);
  }
  if (const std::string bad = ValidateStatsRequest(q); !bad.empty())
    return Send(res, BadRequest("bad_request", bad));
  nlohmann::json report;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    report = StatsReport(*c.db, q);
  }
  Send(res, HttpReply{200, report});
}

void GetDetectability(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  double k_fixture = 0.0, limit_sigmas = 3.0, required_sigmas = 3.0;
  for (auto [name, target] : {std::pair<const char*, double*>{"k_fixture", &k_fixture},
                              {"limit_sigmas", &limit_sigmas},
                              {"required_sigmas", &required_sigmas}}) {
    if (!req.has_param(name)) continue;
    const std::string v = req.get_param_value(name);
    char* end = nullptr;
    const double x = std::strtod(v.c_str(), &end);
    if (v.empty() || *end != '\0' || !(x > 0.0) || !std::isfinite(x))
      return Send(res,
                  BadRequest("bad_parameter",
                             std::string(name) + " must be a positive number, got '" + v + "'"));
    *target = x;
  }
  const auto recipe = c.handlers.current_recipe();
  const analysis::DetectabilitySummary summary = analysis::PredictDetectability(
      DetectabilityOptionsFor(*recipe, k_fixture, limit_sigmas, required_sigmas));
  const std::string source =
      k_fixture > 0.0 ? "k_fixture parameter" : "the chain's default fixture";
  nlohmann::json body = DetectabilityJson(
      summary, source, "the recipe's limits as +-" + nlohmann::json(limit_sigmas).dump() + " sigma",
      required_sigmas);
  body["recipe"] = {{"id", recipe->id}, {"version", recipe->version}, {"hash", recipe->hash}};
  Send(res, HttpReply{summary.usable ? 200 : 422, body});
}

void PostTeach(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto who = RequireRole(req, c.options.tokens, Role::kEngineer, "teach limits");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
  const auto parsed = ParseBody(req);
  if (const ApiError* e = std::get_if<ApiError>(&parsed)) return Send(res, *e);
  const nlohmann::json& body = std::get<nlohmann::json>(parsed);
  if (!body.is_object() || !body.contains("serials") || !body["serials"].is_array() ||
      body["serials"].empty())
    return Send(res, BadRequest("bad_request", "body must be {\"serials\": [\"...\", ...]}"));
  analysis::TeachOptions options;
  try {
    options.method = body.value("method", options.method);
    options.confidence = body.value("confidence", options.confidence);
    options.coverage = body.value("coverage", options.coverage);
    options.allow_few_units = body.value("allow_few_units", options.allow_few_units);
  } catch (const std::exception& e) {
    return Send(res, BadRequest("bad_request", std::string("options: ") + e.what()));
  }
  std::string why;
  if (!options.IsValid(&why)) return Send(res, BadRequest("bad_request", "options: " + why));
  std::vector<std::string> serials;
  for (const auto& s : body["serials"]) {
    if (!s.is_string())
      return Send(res, BadRequest("bad_serial", "serials: " + s.dump() + ": must be a string"));
    serials.push_back(s.get<std::string>());
  }
  const auto recipe = c.handlers.current_recipe();
  Send(res, TeachReply(TeachFromStore(*c.db, c.db_mu, *recipe, serials, options)));
}

}  // namespace

HttpReply TeachReply(const TeachResult& result) {
  using Kind = TeachResult::Kind;
  switch (result.kind) {
    case Kind::kProposed:
      return {200, result.report};
    case Kind::kNotUsable:
      return {422, result.report};
    case Kind::kBadSerial:
      return ToReply({ApiErrorKind::kBadRequest, "bad_serial", result.message});
    case Kind::kInvalidRecipe:
      return ToReply({ApiErrorKind::kUnprocessable, "invalid_recipe", result.message});
  }
  return ToReply({ApiErrorKind::kInternal, "internal", "unknown teach result"});
}

void AddQcRoutes(httplib::Server& s, ApiContext& c) {
  s.Get("/api/stats", Bind(c, GetStats));
  s.Get("/api/detectability", Bind(c, GetDetectability));
  s.Post("/api/teach", Bind(c, PostTeach));
}

}  // namespace eol::station::http
