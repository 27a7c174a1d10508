// The HTTP layer alone (station/daemon/http/): who may call a route (RequireRole), reading a body
// (ParseBody), and the mapping of the station's typed results (RecipeChange, TeachResult) to
// statuses and JSON, first as functions and then through a real server on 127.0.0.1 with a
// real SQLite store.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "db/store.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"
#include "station/daemon/http_api.h"
#include "tests/support/child_process.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

constexpr char kOperatorToken[] = "operator-token-0123456789";
constexpr char kEngineerToken[] = "engineer-token-0123456789";

std::vector<ApiToken> Tokens() {
  return {{"line-op", Role::kOperator, kOperatorToken},
          {"qe-anna", Role::kEngineer, kEngineerToken}};
}

httplib::Request WithToken(const std::string& token) {
  httplib::Request req;
  if (!token.empty()) req.headers.emplace("Authorization", "Bearer " + token);
  return req;
}

// The error RequireRole answers with, or "ok <name>" when it lets the caller through.
std::string Check(const httplib::Request& req, const std::vector<ApiToken>& tokens, Role role) {
  const auto who = RequireRole(req, tokens, role, "change recipes");
  if (const ApiError* e = std::get_if<ApiError>(&who))
    return std::to_string(HttpStatus(e->kind)) + " " + e->code + ": " + e->message;
  return "ok " + std::get<ApiToken>(who).name;
}

TEST(RequireRole, EngineerRoutesNeedAnEngineersToken) {
  EXPECT_EQ(Check(WithToken(""), Tokens(), Role::kEngineer),
            "401 unauthorized: an engineer's bearer token is required");
  EXPECT_EQ(Check(WithToken("not-a-configured-token-000"), Tokens(), Role::kEngineer),
            "401 unauthorized: an engineer's bearer token is required");
  EXPECT_EQ(Check(WithToken(kOperatorToken), Tokens(), Role::kEngineer),
            "403 forbidden: only engineers may change recipes");
  EXPECT_EQ(Check(WithToken(kEngineerToken), Tokens(), Role::kEngineer), "ok qe-anna");
  // No tokens configured does not open engineer routes.
  EXPECT_EQ(Check(WithToken(kEngineerToken), {}, Role::kEngineer),
            "401 unauthorized: an engineer's bearer token is required");
  // Only "Bearer <token>" counts.
  httplib::Request basic;
  basic.headers.emplace("Authorization", std::string("Basic ") + kEngineerToken);
  EXPECT_EQ(Check(basic, Tokens(), Role::kEngineer),
            "401 unauthorized: an engineer's bearer token is required");
}

TEST(RequireRole, OperatorRoutesTakeAnyTokenAndAreOpenWithoutTokens) {
  EXPECT_EQ(Check(WithToken(""), Tokens(), Role::kOperator),
            "401 unauthorized: a valid bearer token is required");
  EXPECT_EQ(Check(WithToken("not-a-configured-token-000"), Tokens(), Role::kOperator),
            "401 unauthorized: a valid bearer token is required");
  EXPECT_EQ(Check(WithToken(kOperatorToken), Tokens(), Role::kOperator), "ok line-op");
  EXPECT_EQ(Check(WithToken(kEngineerToken), Tokens(), Role::kOperator), "ok qe-anna");
  EXPECT_EQ(Check(WithToken(""), {}, Role::kOperator), "ok anonymous");
}

TEST(ParseBody, ReadsJsonAndRefusesWhatIsNotJsonOrTooLarge) {
  httplib::Request req;
  req.body = R"({"serial": "A-1"})";
  auto body = ParseBody(req);
  ASSERT_TRUE(std::holds_alternative<nlohmann::json>(body));
  EXPECT_EQ(std::get<nlohmann::json>(body)["serial"], "A-1");

  req.body = "serial=A-1";
  body = ParseBody(req);
  ASSERT_TRUE(std::holds_alternative<ApiError>(body));
  EXPECT_EQ(ToReply(std::get<ApiError>(body)).status, 400);
  EXPECT_EQ(std::get<ApiError>(body).code, "bad_json");

  req.body = "[" + std::string(100, ' ') + "]";
  body = ParseBody(req, 64);
  ASSERT_TRUE(std::holds_alternative<ApiError>(body));
  EXPECT_EQ(ToReply(std::get<ApiError>(body)).status, 413);
  EXPECT_EQ(std::get<ApiError>(body).message, "request body is 102 bytes; the limit is 64");
  EXPECT_TRUE(std::holds_alternative<nlohmann::json>(ParseBody(req, 102)));
}

TEST(ToReply, EachErrorKindHasItsStatusAndTheErrorBody) {
  const std::vector<std::pair<ApiErrorKind, int>> kinds = {
      {ApiErrorKind::kBadRequest, 400},    {ApiErrorKind::kUnauthorized, 401},
      {ApiErrorKind::kForbidden, 403},     {ApiErrorKind::kNotFound, 404},
      {ApiErrorKind::kConflict, 409},      {ApiErrorKind::kTooLarge, 413},
      {ApiErrorKind::kUnprocessable, 422}, {ApiErrorKind::kInternal, 500}};
  for (const auto& [kind, status] : kinds) {
    const HttpReply r = ToReply({kind, "some_code", "some message"});
    EXPECT_EQ(r.status, status);
    EXPECT_EQ(r.body, nlohmann::json::parse(
                          R"({"error": {"code": "some_code", "message": "some message"}})"));
  }
}

RecipeChange Refused(RecipeChange::Kind kind) {
  RecipeChange c;
  c.kind = kind;
  c.message = "because";
  return c;
}

RecipeChange Changed() {
  RecipeChange c;
  c.kind = RecipeChange::Kind::kChanged;
  c.id = "pmsm-10pole";
  c.version = 2;
  c.hash = "new-hash";
  c.path = "/etc/eol/pmsm-10pole.json";
  c.previous_version = 1;
  c.previous_hash = "old-hash";
  c.kept_as = "/etc/eol/pmsm-10pole.v1.json";
  return c;
}

TEST(RecipeChangeReply, EachKindMapsToItsStatusAndCode) {
  using Kind = RecipeChange::Kind;
  const std::vector<std::tuple<Kind, int, std::string>> refusals = {
      {Kind::kInvalid, 400, "invalid_recipe"},
      {Kind::kBusy, 409, "busy"},
      {Kind::kWrongRecipe, 409, "wrong_recipe"},
      {Kind::kVersionNotIncreased, 409, "version_not_increased"},
      {Kind::kIoError, 500, "recipe_not_written"}};
  for (const auto& [kind, status, code] : refusals) {
    const HttpReply r = RecipeChangeReply(Refused(kind));
    EXPECT_EQ(r.status, status) << code;
    EXPECT_EQ(r.body["error"]["code"], code);
    EXPECT_EQ(r.body["error"]["message"], "because");
  }
  const HttpReply ok = RecipeChangeReply(Changed());
  EXPECT_EQ(ok.status, 200);
  EXPECT_EQ(ok.body, nlohmann::json::parse(R"({
      "id": "pmsm-10pole", "version": 2, "hash": "new-hash",
      "path": "/etc/eol/pmsm-10pole.json",
      "previous": {"version": 1, "hash": "old-hash",
                   "kept_as": "/etc/eol/pmsm-10pole.v1.json"}})"));
}

TEST(TeachReply, EachKindMapsToItsStatus) {
  using Kind = TeachResult::Kind;
  TeachResult r;
  r.report = {{"usable", true}};
  r.kind = Kind::kProposed;
  EXPECT_EQ(TeachReply(r).status, 200);
  EXPECT_EQ(TeachReply(r).body, r.report);
  r.kind = Kind::kNotUsable;
  EXPECT_EQ(TeachReply(r).status, 422);
  EXPECT_EQ(TeachReply(r).body, r.report);
  r.message = "serials: \"a b\": bad";
  r.kind = Kind::kBadSerial;
  EXPECT_EQ(TeachReply(r).status, 400);
  EXPECT_EQ(TeachReply(r).body["error"]["code"], "bad_serial");
  r.kind = Kind::kInvalidRecipe;
  EXPECT_EQ(TeachReply(r).status, 422);
  EXPECT_EQ(TeachReply(r).body["error"]["code"], "invalid_recipe");
}

// PUT /api/recipe through a real server: the route checks the role and the body before it
// asks the station, and answers each RecipeChange with its status.
TEST(HttpTransport, PutRecipeChecksRoleAndBodyThenMapsTheStationsAnswer) {
  eol::testing::TempDir dir;
  db::Store::Open(dir / "s.sqlite");  // the API reads; the station's writer creates the file
  StatusBoard board("http-transport");
  HttpOptions o;
  o.port = 0;
  o.db_path = dir / "s.sqlite";
  o.tokens = Tokens();
  HttpHandlers h;
  int asked = 0;
  RecipeChange next = Changed();
  std::string who;
  h.change_recipe = [&](const nlohmann::json& recipe, const ApiToken& token) {
    ++asked;
    who = token.name + " " + ToString(token.role) + " " + recipe.value("id", "");
    return next;
  };
  HttpApi api(board, o, h);
  api.Start();
  httplib::Client client("127.0.0.1", api.port());
  auto put = [&](const char* token, const std::string& body) {
    httplib::Headers headers;
    if (token) headers.emplace("Authorization", std::string("Bearer ") + token);
    auto res = client.Put("/api/recipe", headers, body, "application/json");
    if (!res) return std::string("no answer");
    std::string code;
    if (!res->body.empty()) {
      const auto j = nlohmann::json::parse(res->body, nullptr, false);
      if (j.contains("error")) code = j["error"]["code"];
    }
    return std::to_string(res->status) + " " + code;
  };
  const std::string recipe = R"({"id": "pmsm-10pole"})";
  EXPECT_EQ(put(nullptr, recipe), "401 unauthorized");
  EXPECT_EQ(put("wrong-token-000000000000", recipe), "401 unauthorized");
  EXPECT_EQ(put(kOperatorToken, recipe), "403 forbidden");
  EXPECT_EQ(put(kEngineerToken, "{not json"), "400 bad_json");
  // Above the server's 64 KiB limit the request is refused before any handler runs.
  EXPECT_EQ(put(kEngineerToken, std::string(kMaxBodyBytes + 1, ' ')), "413 too_large");
  EXPECT_EQ(asked, 0) << "the station was asked although the route refused";

  EXPECT_EQ(put(kEngineerToken, recipe), "200 ");
  EXPECT_EQ(who, "qe-anna engineer pmsm-10pole");
  using Kind = RecipeChange::Kind;
  for (const auto& [kind, expected] : std::vector<std::pair<Kind, std::string>>{
           {Kind::kInvalid, "400 invalid_recipe"},
           {Kind::kBusy, "409 busy"},
           {Kind::kWrongRecipe, "409 wrong_recipe"},
           {Kind::kVersionNotIncreased, "409 version_not_increased"},
           {Kind::kIoError, "500 recipe_not_written"}}) {
    next = Refused(kind);
    EXPECT_EQ(put(kEngineerToken, recipe), expected);
  }
  EXPECT_EQ(asked, 6);
  api.Stop();
}

}  // namespace
}  // namespace eol::station::http
