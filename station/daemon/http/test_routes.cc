// Tests: start one, read the stored ones by serial, by id, or by query.
#include <charconv>

#include "db/serial_number.h"
#include "station/daemon/central/central_record.h"
#include "station/daemon/central/pg.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

ApiError BadRequest(std::string code, std::string message) {
  return {ApiErrorKind::kBadRequest, std::move(code), std::move(message)};
}

// scope=station (the default): this station's store. scope=plant: every station's tests
// from the central record (station/daemon/central/), each with its station_id; the same record
// fields. 400 without a central record configured, 503 when it cannot be read now.
void GetUnit(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string serial = req.matches[1];
  std::string why;
  if (!db::ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  const std::string scope = req.has_param("scope") ? req.get_param_value("scope") : "station";
  if (scope != "station" && scope != "plant")
    return Send(res, BadRequest("bad_scope", "scope must be station or plant"));
  std::vector<db::TestRecord> tests;
  if (scope == "plant") {
    if (c.options.central_postgres.empty())
      return Send(res, BadRequest("bad_scope",
                                  "scope=plant needs a \"central\" block in the station config"));
    try {
      auto pg = central::PgConnection::Connect(c.options.central_postgres, 5, "api");
      tests = central::CentralTestsOfSerial(*pg, serial, false);
    } catch (const central::PgError& e) {
      return Send(res, ApiError{ApiErrorKind::kUnavailable, "central_unavailable", e.what()});
    }
  } else {
    std::lock_guard<std::mutex> lock(c.db_mu);
    tests = c.db->TestsOfSerial(serial, false);
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& t : tests) list.push_back(t);
  Send(res, HttpReply{200, {{"serial", serial}, {"scope", scope}, {"tests", list}}});
}

void GetTest(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  std::int64_t id = 0;
  const std::string text = req.matches[1];
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), id);
  if (ec != std::errc() || end != text.data() + text.size())
    return Send(res, BadRequest("bad_id", "test id '" + text + "' is not a 64-bit whole number"));
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
  long long limit = q.limit;
  for (const auto& e : {TimeParam(req, "from", &q.from), TimeParam(req, "to", &q.to),
                        IntegerParam(req, "limit", 1, 10000, &limit)})
    if (e) return Send(res, *e);
  q.limit = static_cast<int>(limit);
  if (q.from && q.to && !(*q.from < *q.to))
    return Send(res, BadRequest("bad_request", "from must be before to"));
  if (req.has_param("serial")) q.serial = req.get_param_value("serial");
  // "outcome", as records name it; "verdict" is its older name, still accepted.
  if (req.has_param("outcome") && req.has_param("verdict"))
    return Send(res,
                BadRequest("bad_outcome", "give outcome or verdict (its older name), not both"));
  for (const std::string name : {"outcome", "verdict"}) {
    if (!req.has_param(name)) continue;
    q.outcome = analysis::ParseOutcome(req.get_param_value(name));
    if (!q.outcome)
      return Send(res, BadRequest("bad_" + name, name + " must be PASS, FAIL, ERROR or ABORTED"));
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
  if (!db::ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  TestRequest request{serial, {}, {}};
  if (!ReadWorkContext(body, &request.work, &why)) return Send(res, BadRequest("bad_field", why));
  if (body.contains("variant") && !body["variant"].is_null()) {
    if (!body["variant"].is_string() || body["variant"].get<std::string>().empty())
      return Send(res, BadRequest("bad_field", "variant: must be a non-empty string"));
    request.variant.name = body["variant"].get<std::string>();
  }
  VariantRefusal variant = VariantRefusal::kNone;
  if (!c.handlers.start_test(request, &why, &variant)) {
    if (variant == VariantRefusal::kNone)
      return Send(res, ApiError{ApiErrorKind::kConflict, "busy", why});
    // Nothing was started: the choice or the serial does not name a variant (400), or the two
    // name different ones (409: the part in the fixture may not be the one chosen).
    const ApiErrorKind kind =
        variant == VariantRefusal::kConflict ? ApiErrorKind::kConflict : ApiErrorKind::kBadRequest;
    return Send(res, ApiError{kind, ToString(variant), why});
  }
  Send(res, HttpReply{202, {{"serial", serial}, {"accepted", true}}});
}

}  // namespace

void AddTestRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "GET", R"(/api/units/([^/]+))", GetUnit);
  Route(s, c, "GET", R"(/api/tests/(\d+))", GetTest);
  Route(s, c, "GET", "/api/tests", GetTests);
  Route(s, c, "POST", "/api/tests", PostTest);
}

}  // namespace eol::station::http
