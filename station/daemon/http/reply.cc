#include "station/daemon/http/reply.h"

#include <httplib.h>

namespace eol::station::http {

int HttpStatus(ApiErrorKind kind) {
  switch (kind) {
    case ApiErrorKind::kBadRequest:
      return 400;
    case ApiErrorKind::kUnauthorized:
      return 401;
    case ApiErrorKind::kForbidden:
      return 403;
    case ApiErrorKind::kNotFound:
      return 404;
    case ApiErrorKind::kMethodNotAllowed:
      return 405;
    case ApiErrorKind::kConflict:
      return 409;
    case ApiErrorKind::kLengthRequired:
      return 411;
    case ApiErrorKind::kTooLarge:
      return 413;
    case ApiErrorKind::kUnsupportedMedia:
      return 415;
    case ApiErrorKind::kMisdirected:
      return 421;
    case ApiErrorKind::kUnprocessable:
      return 422;
    case ApiErrorKind::kInternal:
      return 500;
    case ApiErrorKind::kUnavailable:
      return 503;
  }
  return 500;
}

HttpReply ToReply(const ApiError& error) {
  return {HttpStatus(error.kind), {{"error", {{"code", error.code}, {"message", error.message}}}}};
}

void Send(httplib::Response& res, const HttpReply& reply) {
  res.status = reply.status;
  res.set_content(reply.body.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace),
                  "application/json");
}

void Send(httplib::Response& res, const ApiError& error) { Send(res, ToReply(error)); }

std::string RawErrorResponse(int status, const char* reason, const std::string& code,
                             const std::string& message, bool retry_after) {
  const nlohmann::json error = {{"error", {{"code", code}, {"message", message}}}};
  const std::string body = error.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return "HTTP/1.1 " + std::to_string(status) + " " + reason +
         "\r\nContent-Type: application/json\r\n" + (retry_after ? "Retry-After: 1\r\n" : "") +
         "Connection: close\r\nContent-Security-Policy: frame-ancestors 'none'\r\n"
         "X-Frame-Options: DENY\r\nContent-Length: " +
         std::to_string(body.size()) + "\r\n\r\n" + body;
}

}  // namespace eol::station::http
