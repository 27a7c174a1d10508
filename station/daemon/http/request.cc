#include "station/daemon/http/request.h"

#include <httplib.h>

#include <algorithm>
#include <charconv>

#include "db/clock.h"

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
  if (JsonNestingDepth(req.body, kMaxJsonDepth) > kMaxJsonDepth)
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kBadRequest, "too_deep",
                           "request body nests arrays and objects deeper than " +
                               std::to_string(kMaxJsonDepth) + " levels"});
  try {
    return Result(std::in_place_type<nlohmann::json>, nlohmann::json::parse(req.body));
  } catch (const nlohmann::json::exception&) {
    return Result(std::in_place_type<ApiError>,
                  ApiError{ApiErrorKind::kBadRequest, "bad_json", "request body is not JSON"});
  }
}

int JsonNestingDepth(std::string_view text, int stop_above) {
  int depth = 0, deepest = 0;
  bool in_string = false, escaped = false;
  for (const char c : text) {
    if (in_string) {
      if (escaped) {
        escaped = false;
      } else if (c == '\\') {
        escaped = true;
      } else if (c == '"') {
        in_string = false;
      }
    } else if (c == '"') {
      in_string = true;
    } else if (c == '[' || c == '{') {
      deepest = std::max(deepest, ++depth);
      if (deepest > stop_above) return deepest;
    } else if (c == ']' || c == '}') {
      --depth;
    }
  }
  return deepest;
}

std::string Excerpt(const nlohmann::json& value, std::size_t max_chars) {
  std::string text = value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  if (text.size() > max_chars) text = text.substr(0, max_chars) + "...";
  return text;
}

namespace {

ApiError BadParam(const std::string& name, std::string message) {
  return {ApiErrorKind::kBadRequest, "bad_" + name, std::move(message)};
}

template <typename T>
std::string RangeText(T lo, T hi) {
  return "[" + nlohmann::json(lo).dump() + ", " + nlohmann::json(hi).dump() + "]";
}

}  // namespace

std::optional<ApiError> IntegerParam(const httplib::Request& req, const std::string& name,
                                     long long lo, long long hi, long long* out) {
  if (!req.has_param(name.c_str())) return std::nullopt;
  const std::string v = req.get_param_value(name.c_str());
  long long x = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (v.empty() || ec != std::errc() || end != v.data() + v.size() || x < lo || x > hi)
    return BadParam(name,
                    name + " must be a whole number in " + RangeText(lo, hi) + ", got '" + v + "'");
  *out = x;
  return std::nullopt;
}

std::optional<ApiError> NumberParam(const httplib::Request& req, const std::string& name, double lo,
                                    double hi, double* out) {
  if (!req.has_param(name.c_str())) return std::nullopt;
  const std::string v = req.get_param_value(name.c_str());
  double x = 0;
  const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
  if (v.empty() || ec != std::errc() || end != v.data() + v.size() || !(x >= lo && x <= hi))
    return BadParam(name, name + " must be a number in " + RangeText(lo, hi) + ", got '" + v + "'");
  *out = x;
  return std::nullopt;
}

std::optional<ApiError> TimeParam(const httplib::Request& req, const std::string& name,
                                  std::optional<std::string>* out) {
  if (!req.has_param(name.c_str())) return std::nullopt;
  std::string why;
  const auto t = db::NormaliseIso8601(req.get_param_value(name.c_str()), &why);
  if (!t) return BadParam(name, name + ": " + why);
  *out = *t;
  return std::nullopt;
}

}  // namespace eol::station::http
