// The recipe in use: read it, change it (engineers; audited), and read the audit log.
#include "db/clock.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http/routes.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

void GetRecipe(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  Send(res, HttpReply{200, c.handlers.recipe()});
}

void PutRecipe(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto who = RequireRole(req, c.options.tokens, Role::kEngineer, "change recipes");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
  const auto body = ParseBody(req);
  if (const ApiError* e = std::get_if<ApiError>(&body)) return Send(res, *e);
  Send(res, RecipeChangeReply(
                c.handlers.change_recipe(std::get<nlohmann::json>(body), std::get<ApiToken>(who))));
}

// POST /api/recipe/approve {"recipe": <a proposal>, "note"?: text}: the engineer whose token
// it is approves the proposal, and it is installed as PUT /api/recipe would (validated,
// audited under the engineer's name, in use for the next test).
void ApproveRecipe(ApiContext& c, const httplib::Request& req, httplib::Response& res) {
  const auto who = RequireRole(req, c.options.tokens, Role::kEngineer, "approve recipes");
  if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
  const auto body = ParseBody(req);
  if (const ApiError* e = std::get_if<ApiError>(&body)) return Send(res, *e);
  const nlohmann::json& b = std::get<nlohmann::json>(body);
  auto bad = [&](const std::string& why) {
    Send(res, ApiError{ApiErrorKind::kBadRequest, "invalid_approval", why});
  };
  if (!b.is_object() || !b.contains("recipe") || !b.at("recipe").is_object())
    return bad("the body is {\"recipe\": <the proposed recipe>, \"note\": text (optional)}");
  nlohmann::json recipe = b.at("recipe");
  if (!recipe.contains("approval") || !recipe.at("approval").is_object() ||
      recipe.at("approval").value("state", "") != "proposed")
    return bad("/recipe/approval/state: is not \"proposed\": only a proposal is approved");
  nlohmann::json approval = {
      {"state", "approved"}, {"by", std::get<ApiToken>(who).name}, {"at", db::UtcNowIso8601()}};
  if (b.contains("note")) {
    if (!b.at("note").is_string()) return bad("/note: must be text");
    approval["note"] = b.at("note");
  }
  recipe["approval"] = approval;
  Send(res, RecipeChangeReply(c.handlers.change_recipe(recipe, std::get<ApiToken>(who))));
}

void GetVariants(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  Send(res,
       HttpReply{200, c.handlers.variants ? c.handlers.variants()
                                          : nlohmann::json{{"variants", nlohmann::json::array()}}});
}

void GetAudit(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  std::vector<db::RecipeAudit> log;
  {
    std::lock_guard<std::mutex> lock(c.db_mu);
    log = c.db->AuditLog(100);
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
  Send(res, HttpReply{200, {{"audit", list}}});
}

}  // namespace

HttpReply RecipeChangeReply(const RecipeChange& change) {
  using Kind = RecipeChange::Kind;
  switch (change.kind) {
    case Kind::kChanged:
      return {200,
              {{"id", change.id},
               {"version", change.version},
               {"hash", change.hash},
               {"path", change.path},
               {"previous",
                {{"version", change.previous_version},
                 {"hash", change.previous_hash},
                 {"kept_as", change.kept_as}}}}};
    case Kind::kInvalid:
      return ToReply({ApiErrorKind::kBadRequest, "invalid_recipe", change.message});
    case Kind::kNotApproved:
      return ToReply({ApiErrorKind::kConflict, "recipe_not_approved", change.message});
    case Kind::kBusy:
      return ToReply({ApiErrorKind::kConflict, "busy", change.message});
    case Kind::kWrongRecipe:
      return ToReply({ApiErrorKind::kConflict, "wrong_recipe", change.message});
    case Kind::kVersionNotIncreased:
      return ToReply({ApiErrorKind::kConflict, "version_not_increased", change.message});
    case Kind::kIoError:
      return ToReply({ApiErrorKind::kInternal, "recipe_not_written", change.message});
  }
  return ToReply({ApiErrorKind::kInternal, "internal", "unknown recipe change result"});
}

void AddRecipeRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "GET", "/api/recipe", GetRecipe);
  Route(s, c, "PUT", "/api/recipe", PutRecipe);
  Route(s, c, "GET", "/api/recipe/audit", GetAudit);
  Route(s, c, "POST", "/api/recipe/approve", ApproveRecipe);
  Route(s, c, "GET", "/api/variants", GetVariants);
}

}  // namespace eol::station::http
