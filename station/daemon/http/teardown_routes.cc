// Teardown findings of a unit (engineers record them; audited, append-only), what they say
// about the station's verdicts, and the unit's printable report.
#include <charconv>

#include "db/clock.h"
#include "db/serial_number.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"
#include "station/daemon/version.h"
#include "station/reports/teardown_review.h"
#include "station/reports/unit_report.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

ApiError BadRequest(std::string code, std::string message) {
  return {ApiErrorKind::kBadRequest, std::move(code), std::move(message)};
}

nlohmann::json WithVerdict(db::Store& store, const db::TeardownEntry& e) {
  nlohmann::json j = TeardownJson(e);
  const auto t = e.test_id ? store.Test(*e.test_id, false) : std::nullopt;
  j["verdict"] = t ? nlohmann::json(analysis::ToString(t->outcome)) : nlohmann::json();
  return j;
}

void GetTeardowns(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string serial = req.matches[1];
  std::string why;
  if (!db::ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  nlohmann::json list = nlohmann::json::array();
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    for (const db::TeardownEntry& e : c.db->TeardownsOfSerial(serial))
      list.push_back(WithVerdict(*c.db, e));
  }
  const nlohmann::json current = list.empty() ? nlohmann::json() : list.back();
  Send(res, HttpReply{200, {{"serial", serial}, {"teardowns", list}, {"current", current}}});
}

// POST {"found": "defective" | "not-defective", "note"?: text}: recorded under the name of
// the engineer's token, at the station's time.
void PostTeardown(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto who = RequireRole(req, c.options.tokens, Role::kEngineer, "record teardown findings");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
  const std::string serial = req.matches[1];
  std::string why;
  if (!db::ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  const auto body = ParseBody(req);
  if (const ApiError* e = std::get_if<ApiError>(&body)) return Send(res, *e);
  const nlohmann::json& b = std::get<nlohmann::json>(body);
  const auto bad = [&](const std::string& m) { Send(res, BadRequest("invalid_teardown", m)); };
  if (!b.is_object() || !b.contains("found") || !b.at("found").is_string())
    return bad("the body is {\"found\": \"defective\" | \"not-defective\", \"note\": text}");
  const auto found = db::ParseTeardownFinding(b.at("found").get<std::string>());
  if (!found)
    return bad("/found: " + Excerpt(b.at("found")) + " is not \"defective\" or \"not-defective\"");
  if (b.contains("note") && !b.at("note").is_string()) return bad("/note: must be text");
  db::TeardownEntry e;
  e.serial = serial;
  e.found = *found;
  e.note = b.value("note", "");
  e.by = std::get<ApiToken>(who).name;
  e.at = db::UtcNowIso8601();
  nlohmann::json stored;
  try {
    std::lock_guard<std::mutex> lock(c.db_mu);
    stored = WithVerdict(*c.db, c.db->AppendTeardown(e));
  } catch (const std::invalid_argument& x) {  // a serial never tested here
    return Send(res, ApiError{ApiErrorKind::kNotFound, "unknown_serial", x.what()});
  }
  Send(res, HttpReply{201, stored});
}

void GetTeardownReview(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  double confidence = 0.95;
  if (auto e = NumberParam(req, "confidence", 0.5, 0.999999, &confidence)) return Send(res, *e);
  std::lock_guard<std::mutex> lock(c.db_mu);
  Send(res, HttpReply{200, ReviewJson(ReviewTeardowns(*c.db, confidence))});
}

// GET /api/units/{serial}/report.pdf?test_id=N: the newest finished test or test N.
void GetReport(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const std::string serial = req.matches[1];
  std::string why;
  if (!db::ValidSerial(serial, &why)) return Send(res, BadRequest("bad_serial", why));
  long long test_id = 0;
  if (auto e = IntegerParam(req, "test_id", 1, INT64_MAX, &test_id)) return Send(res, *e);
  const std::shared_ptr<const Recipe> recipe =
      c.handlers.current_recipe ? c.handlers.current_recipe() : nullptr;
  UnitReport report;
  try {
    std::lock_guard<std::mutex> lock(c.db_mu);
    report = LoadUnitReport(*c.db, serial, test_id, recipe ? recipe->hash : "",
                            recipe ? recipe->masks : std::vector<analysis::CurveMask>{});
  } catch (const std::out_of_range& x) {
    return Send(res, ApiError{ApiErrorKind::kNotFound, "not_found", x.what()});
  }
  if (recipe && report.masks.empty() && report.test.recipe_hash != recipe->hash)
    report.masks_note = "masks not drawn: the recipe in use is not this test's";
  report.printed_at = db::UtcNowIso8601();
  report.printed_by_software = SoftwareVersion();
  res.status = 200;
  res.set_header("Content-Disposition", "inline; filename=\"" + serial + ".pdf\"");
  res.set_content(RenderUnitReportPdf(report), "application/pdf");
}

}  // namespace

void AddTeardownRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "GET", R"(/api/units/([^/]+)/teardown)", GetTeardowns);
  Route(s, c, "POST", R"(/api/units/([^/]+)/teardown)", PostTeardown);
  Route(s, c, "GET", "/api/teardown/review", GetTeardownReview);
  Route(s, c, "GET", R"(/api/units/([^/]+)/report\.pdf)", GetReport);
}

}  // namespace eol::station::http
