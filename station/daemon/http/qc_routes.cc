// Quality engineering: capability and gauge statistics, control charts, detectability of
// defect classes, and limits taught from stored good units.
#include <algorithm>
#include <set>

#include "analysis/qc/measurement_names.h"
#include "drivers/io/chart.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"
#include "station/reports/spc_charts.h"
#include "station/reports/stats_report.h"
#include "station/reports/yield.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

ApiError BadRequest(std::string code, std::string message) {
  return {ApiErrorKind::kBadRequest, std::move(code), std::move(message)};
}

void GetStats(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  StatsRequest q;
  for (const auto& e : {TimeParam(req, "from", &q.from), TimeParam(req, "to", &q.to)})
    if (e) return Send(res, *e);
  if (req.has_param("recipe_hash")) q.recipe_hash = req.get_param_value("recipe_hash");
  if (req.has_param("gauge")) q.gauge_serial = req.get_param_value("gauge");
  std::string why;
  for (std::size_t i = 0; i < req.get_param_value_count("reference"); ++i)
    if (!ParseReference(req.get_param_value("reference", i), q.reference, &why))
      return Send(res, BadRequest("bad_reference", why));
  if (req.has_param("population") &&
      !ParsePopulation(req.get_param_value("population"), &q.population))
    return Send(res, BadRequest("bad_population", "population must be all or pass"));
  long long subgroup = 1, baseline = static_cast<long long>(q.baseline);
  for (const auto& e : {IntegerParam(req, "subgroup", 1, 10, &subgroup),
                        IntegerParam(req, "baseline", 2, 100000, &baseline)})
    if (e) return Send(res, *e);
  q.subgroup = static_cast<std::size_t>(subgroup);
  q.baseline = static_cast<std::size_t>(baseline);
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

// GET /api/charts/<measurement>.svg?chart=imr|xbar_r|histogram&from=&to=&last=&subgroup=
//   &population=all|pass&baseline=&recipe_hash=: the chart as image/svg+xml
//   (station/reports/spc_charts.h).
// Unknown parameters are refused (a misspelt "subgrup" would otherwise draw the default).
void GetChart(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  static const std::set<std::string> kKnown = {"chart",    "from",       "to",       "last",
                                               "subgroup", "population", "baseline", "recipe_hash"};
  for (const auto& [name, value] : req.params)
    if (!kKnown.count(name))
      return Send(res, BadRequest("unknown_parameter",
                                  "unknown parameter '" + name +
                                      "' (chart, from, to, last, subgroup, population, "
                                      "baseline, recipe_hash)"));
  ChartRequest q;
  q.measurement = req.matches[1];
  if (std::find(analysis::names::kAll.begin(), analysis::names::kAll.end(), q.measurement) ==
      analysis::names::kAll.end())
    return Send(res,
                ApiError{ApiErrorKind::kNotFound, "unknown_measurement", ValidateChartRequest(q)});
  for (const auto& e : {TimeParam(req, "from", &q.from), TimeParam(req, "to", &q.to)})
    if (e) return Send(res, *e);
  long long last = 0, subgroup = 5, baseline = static_cast<long long>(q.baseline);
  for (const auto& e : {IntegerParam(req, "last", 1, 100000, &last),
                        IntegerParam(req, "subgroup", 2, 10, &subgroup),
                        IntegerParam(req, "baseline", 2, 100000, &baseline)})
    if (e) return Send(res, *e);
  q.last = static_cast<std::size_t>(last);
  q.subgroup = static_cast<std::size_t>(subgroup);
  q.baseline = static_cast<std::size_t>(baseline);
  if (req.has_param("chart") && !ParseChartKind(req.get_param_value("chart"), &q.kind))
    return Send(res, BadRequest("bad_chart", "chart must be imr, xbar_r or histogram (have '" +
                                                 req.get_param_value("chart") + "')"));
  if (req.has_param("population") &&
      !ParsePopulation(req.get_param_value("population"), &q.population))
    return Send(res, BadRequest("bad_population", "population must be all or pass (have '" +
                                                      req.get_param_value("population") + "')"));
  if (req.has_param("recipe_hash")) q.recipe_hash = req.get_param_value("recipe_hash");
  if (const std::string bad = ValidateChartRequest(q); !bad.empty())
    return Send(res, BadRequest("bad_request", bad));
  std::optional<SpcSeries> series;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    series = ReadSpcSeries(*c.db, q);
  }
  if (!series)
    return Send(res, ApiError{ApiErrorKind::kNotFound, "no_units",
                              "no production test in the window measured " + q.measurement});
  res.status = 200;
  res.set_content(io::RenderChartSvg(MeasurementChart(*series, q)), "image/svg+xml");
}

// The yield request of GET /api/yield and /api/yield/pareto.svg: from, to, recipe_hash, by,
// shifts, utc_offset_min (station/reports/yield.h), and for the chart `group` (a group's key).
// Unknown parameters are refused (a misspelt "by" would otherwise give the total).
std::optional<ApiError> ParseYieldRequest(const httplib::Request& req, bool chart,
                                          YieldRequest* q) {
  static const std::set<std::string> kKnown = {"from", "to",     "recipe_hash",
                                               "by",   "shifts", "utc_offset_min"};
  for (const auto& [name, value] : req.params)
    if (!kKnown.count(name) && !(chart && name == "group"))
      return BadRequest("unknown_parameter", "unknown parameter '" + name +
                                                 "' (from, to, recipe_hash, by, shifts, "
                                                 "utc_offset_min" +
                                                 (chart ? ", group)" : ")"));
  for (const auto& e : {TimeParam(req, "from", &q->from), TimeParam(req, "to", &q->to)})
    if (e) return e;
  if (q->from && q->to && *q->from >= *q->to)
    return BadRequest("bad_request", "from must be before to");
  if (req.has_param("recipe_hash")) q->recipe_hash = req.get_param_value("recipe_hash");
  if (req.has_param("by") && !ParseYieldGrouping(req.get_param_value("by"), &q->options.by))
    return BadRequest("bad_by", "by must be all, shift, day or recipe (have '" +
                                    req.get_param_value("by") + "')");
  std::string why;
  if (!ParseShifts(req.has_param("shifts") ? req.get_param_value("shifts") : kDefaultShifts,
                   &q->options.shifts, &why))
    return BadRequest("bad_shifts", "shifts: " + why);
  long long offset = 0;
  if (const auto e = IntegerParam(req, "utc_offset_min", -840, 840, &offset)) return e;
  if (req.has_param("utc_offset_min")) q->options.utc_offset_min = static_cast<int>(offset);
  return std::nullopt;
}

// GET /api/yield: station/reports/yield.h's JSON.
void GetYield(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  YieldRequest q;
  if (const auto e = ParseYieldRequest(req, false, &q)) return Send(res, *e);
  nlohmann::json report;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    report = YieldReport(*c.db, q);
  }
  Send(res, HttpReply{200, report});
}

// GET /api/yield/pareto.svg: the Pareto of the window's total, or of the group `group` (by
// `by`), as image/svg+xml; 404 "no_group" for a key the report lacks, 404 "no_failures"
// when the group has no non-PASS test.
void GetParetoSvg(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  YieldRequest q;
  if (const auto e = ParseYieldRequest(req, true, &q)) return Send(res, *e);
  nlohmann::json report;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    report = YieldReport(*c.db, q);
  }
  const nlohmann::json* group = &report["total"];
  if (req.has_param("group") && req.get_param_value("group") != "all") {
    group = nullptr;
    for (const auto& g : report["groups"])
      if (g["key"] == req.get_param_value("group")) group = &g;
    if (!group)
      return Send(res, ApiError{ApiErrorKind::kNotFound, "no_group",
                                "no group '" + req.get_param_value("group") + "' by " +
                                    report["window"]["by"].get<std::string>() + " in the window"});
  }
  if ((*group)["pareto"].empty())
    return Send(res, ApiError{ApiErrorKind::kNotFound, "no_failures",
                              "no non-PASS test in " + (*group)["key"].get<std::string>() +
                                  ": nothing to chart"});
  res.status = 200;
  res.set_content(io::RenderChartSvg(ParetoChart(*group, "Pareto of reasons")), "image/svg+xml");
}

void GetDetectability(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  // Fixtures measured so far are near 1e3 N m/rad; the range allows four decades each way
  // and keeps the model's arithmetic finite (k_fixture=1e308 used to give a 500).
  double k_fixture = 0.0, limit_sigmas = 3.0, required_sigmas = 3.0;
  for (const auto& e : {NumberParam(req, "k_fixture", 0.1, 1e7, &k_fixture),
                        NumberParam(req, "limit_sigmas", 0.5, 20.0, &limit_sigmas),
                        NumberParam(req, "required_sigmas", 0.5, 20.0, &required_sigmas)})
    if (e) return Send(res, *e);
  const auto recipe = c.handlers.current_recipe();
  const analysis::DetectabilityOptions options =
      DetectabilityOptionsFor(*recipe, nullptr, k_fixture, limit_sigmas, required_sigmas);
  if (const std::string why = DetectabilityModelMismatch(*recipe, nullptr); !why.empty())
    return Send(res, ApiError{ApiErrorKind::kUnprocessable, "model_mismatch", why});
  const analysis::DetectabilitySummary summary = analysis::PredictDetectability(options);
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
  bool force_foreign = false;
  try {
    force_foreign = body.value("force_foreign", false);
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
      return Send(res, BadRequest("bad_serial", "serials: " + Excerpt(s) + ": must be a string"));
    serials.push_back(s.get<std::string>());
  }
  const auto recipe = c.handlers.current_recipe();
  Send(res, TeachReply(TeachFromStore(*c.db, c.db_mu, *recipe, serials, options, force_foreign)));
}

}  // namespace

HttpReply TeachReply(const TeachResult& result) {
  using Kind = TeachResult::Kind;
  switch (result.kind) {
    case Kind::kProposed:
      return {200, result.report};
    case Kind::kNotUsable:
      return {422, result.report};
    case Kind::kForeignUnits: {  // the error, and the findings beside it
      HttpReply reply =
          ToReply({ApiErrorKind::kUnprocessable, "foreign_golden_units", result.message});
      reply.body.update(result.report);
      return reply;
    }
    case Kind::kBadSerial:
      return ToReply({ApiErrorKind::kBadRequest, "bad_serial", result.message});
    case Kind::kInvalidRecipe:
      return ToReply({ApiErrorKind::kUnprocessable, "invalid_recipe", result.message});
  }
  return ToReply({ApiErrorKind::kInternal, "internal", "unknown teach result"});
}

void AddQcRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "GET", "/api/stats", GetStats);
  Route(s, c, "GET", R"(/api/charts/([^/]+)\.svg)", GetChart);
  Route(s, c, "GET", "/api/detectability", GetDetectability);
  Route(s, c, "GET", "/api/yield", GetYield);
  Route(s, c, "GET", R"(/api/yield/pareto\.svg)", GetParetoSvg);
  Route(s, c, "POST", "/api/teach", PostTeach);
}

}  // namespace eol::station::http
