// Tests: start one, read the stored ones by serial, by id, or by query.
#include "station/http/request.h"
#include "station/http/routes.h"
#include "station/serial_number.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

ApiError BadRequest(std::string code, std::string message) {
  return {ApiErrorKind::kBadRequest, std::move(code), std::move(message)};
}

void GetUnit(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string serial = req.matches[1];
  std::string why;
  if (!ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  std::vector<db::TestRecord> tests;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    tests = c.db->TestsOfSerial(serial, false);
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& t : tests) list.push_back(t);
  Send(res, HttpReply{200, {{"serial", serial}, {"tests", list}}});
}

void GetTest(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  std::int64_t id = 0;
  try {
    id = std::stoll(req.matches[1]);
  } catch (const std::exception&) {
    return Send(res, BadRequest("bad_id", "test id is not a number"));
  }
  std::optional<db::TestRecord> t;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    t = c.db->Test(id, true);
  }
  if (!t)
    return Send(res, ApiError{ApiErrorKind::kNotFound, "not_found",
                              "no finished test with id " + std::to_string(id)});
  Send(res, HttpReply{200, *t});
}

void GetTests(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  db::TestQuery q;
  if (req.has_param("from")) q.from = req.get_param_value("from");
  if (req.has_param("to")) q.to = req.get_param_value("to");
  if (req.has_param("serial")) q.serial = req.get_param_value("serial");
  if (req.has_param("verdict")) {
    q.outcome = analysis::ParseOutcome(req.get_param_value("verdict"));
    if (!q.outcome)
      return Send(res, BadRequest("bad_verdict", "verdict must be PASS, FAIL, ERROR or ABORTED"));
  }
  if (req.has_param("limit")) {
    try {
      q.limit = std::stoi(req.get_param_value("limit"));
    } catch (const std::exception&) {
      return Send(res, BadRequest("bad_limit", "limit must be a whole number"));
    }
    if (q.limit < 1 || q.limit > 10000)
      return Send(res, BadRequest("bad_limit", "limit must be in [1, 10000]"));
  }
  std::vector<db::TestRecord> tests;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    tests = c.db->Tests(q);
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& t : tests) list.push_back(t);
  Send(res, HttpReply{200, {{"tests", list}}});
}

void PostTest(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto who = RequireRole(req, c.options.tokens, Role::kOperator, "start tests");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
  const auto parsed = ParseBody(req);
  if (const ApiError* e = std::get_if<ApiError>(&parsed)) return Send(res, *e);
  const nlohmann::json& body = std::get<nlohmann::json>(parsed);
  if (!body.is_object() || !body.contains("serial") || !body["serial"].is_string())
    return Send(res, BadRequest("bad_serial", "body must be {\"serial\": \"...\"}"));
  const std::string serial = body["serial"].get<std::string>();
  std::string why;
  if (!ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  if (!c.handlers.start_test(serial, &why))
    return Send(res, ApiError{ApiErrorKind::kConflict, "busy", why});
  Send(res, HttpReply{202, {{"serial", serial}, {"accepted", true}}});
}

}  // namespace

void AddTestRoutes(httplib::Server& s, ApiContext& c) {
  s.Get(R"(/api/units/([^/]+))", Bind(c, GetUnit));
  s.Get(R"(/api/tests/(\d+))", Bind(c, GetTest));
  s.Get("/api/tests", Bind(c, GetTests));
  s.Post("/api/tests", Bind(c, PostTest));
}

}  // namespace eol::station::http
