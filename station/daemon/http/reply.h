// What the HTTP layer answers: a JSON body with a status. Errors are typed (ApiError) and
// turned into {"error": {"code", "message"}} and their status in one place, ToReply().
#pragma once

#include <nlohmann/json.hpp>
#include <string>

namespace httplib {
struct Response;
}

namespace eol::station::http {

// The classes of refusal the API gives, each with one HTTP status.
enum class ApiErrorKind {
  kBadRequest,        // 400: the request is malformed or fails validation
  kUnauthorized,      // 401: no valid bearer token
  kForbidden,         // 403: a valid token whose role may not do this
  kNotFound,          // 404: nothing stored under that key, or no such route
  kMethodNotAllowed,  // 405: the route exists, not with this method
  kConflict,          // 409: refused in the station's current state
  kLengthRequired,    // 411: a body without Content-Length or chunked framing
  kTooLarge,          // 413: the request body exceeds the limit, however it is framed
  kUnsupportedMedia,  // 415: a write route's body is not application/json
  kMisdirected,       // 421: the Host header names no name of this station
  kUnprocessable,     // 422: well-formed, but nothing usable can be made of it
  kInternal,          // 500: the station failed (file system, database, a bug)
  kUnavailable,       // 503: at capacity (event streams, request workers)
};

struct ApiError {
  ApiErrorKind kind = ApiErrorKind::kInternal;
  std::string code;     // machine-readable, stable: "bad_json", "busy", ...
  std::string message;  // for a person: names the field, the value or the cause
};

struct HttpReply {
  int status = 200;
  nlohmann::json body;
};

int HttpStatus(ApiErrorKind kind);

// {"error": {"code": ..., "message": ...}} with the status of the error's kind.
HttpReply ToReply(const ApiError& error);

void Send(httplib::Response& res, const HttpReply& reply);
void Send(httplib::Response& res, const ApiError& error);

// The whole HTTP/1.1 response for a refusal made before httplib has the connection (the head
// reader, the worker pool): {"error": {"code", "message"}}, Connection: close, the framing
// policy every response carries, and Retry-After: 1 when `retry_after`.
std::string RawErrorResponse(int status, const char* reason, const std::string& code,
                             const std::string& message, bool retry_after);

}  // namespace eol::station::http
