#include "station/http/request.h"

#include <httplib.h>

namespace eol::station::http {

std::string BearerToken(const httplib::Request& req) {
  const std::string auth = req.get_header_value("Authorization");
  const std::string prefix = "Bearer ";
  return auth.rfind(prefix, 0) == 0 ? auth.substr(prefix.size()) : "";
}

std::variant<ApiToken, ApiError> RequireRole(const httplib::Request& req,
                                             const std::vector<ApiToken>& tokens, Role role,
                                             std::string_view action) {
  using Result = std::variant<ApiToken, ApiError>;
  const std::string presented = BearerToken(req);
  const ApiToken* who = nullptr;
  if (!presented.empty())
    for (const ApiToken& t : tokens)
      if (t.token == presented) who = &t;
  if (!who) {
    if (role == Role::kOperator && tokens.empty())
      return Result(std::in_place_type<ApiToken>, ApiToken{"anonymous", Role::kOperator, ""});
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kUnauthorized, "unauthorized",
                           role == Role::kEngineer ? "an engineer's bearer token is required"
                                                   : "a valid bearer token is required"});
  }
  // Roles are ordered: a higher one may do everything a lower one may.
  if (static_cast<int>(who->role) < static_cast<int>(role))
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kForbidden, "forbidden",
                           "only " + std::string(ToString(role)) + "s may " + std::string(action)});
  return Result(std::in_place_type<ApiToken>, *who);
}

std::variant<nlohmann::json, ApiError> ParseBody(const httplib::Request& req,
                                                 std::size_t max_bytes) {
  using Result = std::variant<nlohmann::json, ApiError>;
  if (req.body.size() > max_bytes)
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kTooLarge, "too_large",
                           "request body is " + std::to_string(req.body.size()) +
                               " bytes; the limit is " + std::to_string(max_bytes)});
  try {
    return Result(std::in_place_type<nlohmann::json>, nlohmann::json::parse(req.body));
  } catch (const nlohmann::json::exception&) {
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kBadRequest, "bad_json", "request body is not JSON"});
  }
}

}  // namespace eol::station::http
