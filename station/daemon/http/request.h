// Reading a request: who is asking (bearer tokens and roles) and its JSON body. Each returns
// what was asked for or the ApiError to answer with, so a handler's first lines are
//
//   const auto who = RequireRole(req, tokens, Role::kEngineer, "change recipes");
//   if (const ApiError* e = std::get_if<ApiError>(&who)) return Send(res, *e);
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include "station/daemon/config.h"
#include "station/daemon/http/reply.h"

namespace httplib {
struct Request;
}

namespace eol::station::http {

// Request bodies are small JSON documents (a serial, a recipe, a list of serials).
inline constexpr std::size_t kMaxBodyBytes = 64 * 1024;
// The figure routes' bodies carry files (a hits table, FRF curves, a raw recording of a few
// periods): larger, but bounded all the same.
inline constexpr std::size_t kMaxUploadBytes = 4 * 1024 * 1024;

// The token of "Authorization: Bearer <token>", or "" when the header is absent or other.
std::string BearerToken(const httplib::Request& req);

// The configured token the request presents, if its role is at least `role`.
//   no or unknown token: 401 "unauthorized", except that operator routes are open while no
//     tokens are configured (then the caller is {"anonymous", operator});
//   a token of a lower role: 403 "forbidden", "only engineers may <action>".
// Engineer routes always need a token. Token values never appear in messages.
std::variant<ApiToken, ApiError> RequireRole(const httplib::Request& req,
                                             const std::vector<ApiToken>& tokens, Role role,
                                             std::string_view action);

// Arrays and objects nest at most this deep in a request body (a value nested 100,000 deep
// overflowed the stack of the code that printed it).
inline constexpr int kMaxJsonDepth = 64;

// The body as JSON: 413 "too_large" above `max_bytes`, 400 "too_deep" when arrays and objects
// nest deeper than kMaxJsonDepth (found by a scan before parsing), 400 "bad_json" when it
// does not parse.
std::variant<nlohmann::json, ApiError> ParseBody(const httplib::Request& req,
                                                 std::size_t max_bytes = kMaxBodyBytes);

// The deepest nesting of arrays and objects in JSON text (brackets inside strings do not
// count), scanning no further than the first point deeper than `stop_above`.
int JsonNestingDepth(std::string_view text, int stop_above);

// A value as error messages show it: its JSON, cut to `max_chars` with "..." (a rejected
// value is never printed whole).
std::string Excerpt(const nlohmann::json& value, std::size_t max_chars = 200);

// Query parameters, parsed whole (no trailing characters, no exponent for integers, the C
// locale's '.' whatever the locale): absent leaves *out as it was; otherwise a value outside
// [lo, hi] or not a number is 400 "bad_<name>" naming the range and the value.
std::optional<ApiError> IntegerParam(const httplib::Request& req, const std::string& name,
                                     long long lo, long long hi, long long* out);
std::optional<ApiError> NumberParam(const httplib::Request& req, const std::string& name, double lo,
                                    double hi, double* out);
// An ISO 8601 time with its offset, normalised to UTC (db/clock.h NormaliseIso8601).
std::optional<ApiError> TimeParam(const httplib::Request& req, const std::string& name,
                                  std::optional<std::string>* out);

}  // namespace eol::station::http
