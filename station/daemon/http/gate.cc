#include "station/daemon/http/gate.h"

#include <algorithm>
#include <cctype>
#include <charconv>

#include "station/daemon/http/reply.h"
#include "station/daemon/http/request.h"

namespace eol::station::http {
namespace {

std::string Lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return s;
}

std::string Trim(const std::string& s) {
  const auto a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

bool IsWrite(const std::string& method) {
  return method == "POST" || method == "PUT" || method == "PATCH" || method == "DELETE";
}

httplib::Server::HandlerResponse Refuse(httplib::Response& res, ApiErrorKind kind, std::string code,
                                        std::string message, bool close = true) {
  if (close) CloseAfterResponse();
  Send(res, ApiError{kind, std::move(code), std::move(message)});
  return httplib::Server::HandlerResponse::Handled;
}

// The host part of a Host header value ("name:8080" -> "name", "[::1]:80" -> "[::1]").
std::string HostName(const std::string& value) {
  const std::string v = Lower(Trim(value));
  if (!v.empty() && v.front() == '[') return v.substr(0, v.find(']') + 1);
  const std::size_t colon = v.find(':');
  return colon == std::string::npos ? v : v.substr(0, colon);
}

// The Host names this station answers to: loopback names, the listen address, the address
// the client connected to, and the configured names.
bool KnownHost(const ApiContext& c, const httplib::Request& req, const std::string& host) {
  if (host == "localhost" || host == "127.0.0.1" || host == "[::1]") return true;
  const auto same = [&host](std::string address) {
    address = Lower(address);
    if (address.find(':') != std::string::npos) address = "[" + address + "]";
    return !address.empty() && address != "0.0.0.0" && address != "[::]" && host == address;
  };
  if (same(c.options.listen) || same(req.local_addr)) return true;
  return std::any_of(c.options.hosts.begin(), c.options.hosts.end(),
                     [&host](const std::string& h) { return Lower(h) == host; });
}

httplib::Server::HandlerResponse Check(const ApiContext& c, const httplib::Request& req,
                                       httplib::Response& res) {
  // DNS rebinding: a foreign page whose name resolves to this station sends its own name.
  const bool has_body_framing =
      req.has_header("Content-Length") || req.has_header("Transfer-Encoding");
  if (!req.has_header("Host") || req.get_header_value_count("Host") != 1)
    return Refuse(res, ApiErrorKind::kBadRequest, "bad_host",
                  "a request needs exactly one Host header", has_body_framing);
  const std::string host = HostName(req.get_header_value("Host"));
  if (!KnownHost(c, req, host))
    return Refuse(res, ApiErrorKind::kMisdirected, "unknown_host",
                  "Host '" + host.substr(0, 100) +
                      "' is not a name of this station (configure it in http.hosts)",
                  has_body_framing);
  const std::string method = req.method == "HEAD" ? "GET" : req.method;
  std::string allow;
  bool allowed = false;
  std::size_t max_body = kMaxBodyBytes;
  for (const auto& r : c.routes) {
    if (!std::regex_match(req.path, r.pattern)) continue;
    if (r.method == method) {
      allowed = true;
      max_body = r.max_body_bytes;
    }
    if (allow.find(r.method) == std::string::npos) allow += (allow.empty() ? "" : ", ") + r.method;
  }
  const bool static_file =
      method == "GET" && !c.options.web_root.empty() && req.path.rfind("/static/", 0) == 0;
  const std::string te = Lower(Trim(req.get_header_value("Transfer-Encoding")));
  const bool has_length = req.has_header("Content-Length");
  std::uint64_t length = 0;
  if (has_length) {
    const std::string v = Trim(req.get_header_value("Content-Length"));
    const auto [end, ec] = std::from_chars(v.data(), v.data() + v.size(), length);
    if (ec != std::errc() || end != v.data() + v.size() || v.empty())
      return Refuse(res, ApiErrorKind::kBadRequest, "bad_framing",
                    "Content-Length '" + v + "' is not a whole number");
  }
  const bool has_body = !te.empty() || length > 0;
  // The framing first: a body that is not read must not be mistaken for the next request.
  if (!te.empty() && (te != "chunked" || has_length))
    return Refuse(res, ApiErrorKind::kBadRequest, "bad_framing",
                  "Transfer-Encoding must be 'chunked' alone, without Content-Length");
  if (!allowed && !static_file) {
    if (allow.empty())
      return Refuse(res, ApiErrorKind::kNotFound, "not_found",
                    "no route " + req.method + " " + req.path, has_body);
    res.set_header("Allow", allow);
    return Refuse(res, ApiErrorKind::kMethodNotAllowed, "method_not_allowed",
                  req.method + " " + req.path + " is not allowed; allowed: " + allow, has_body);
  }
  if (!IsWrite(method)) {
    if (has_body)
      return Refuse(res, ApiErrorKind::kBadRequest, "unexpected_body",
                    req.method + " requests carry no body");
    return httplib::Server::HandlerResponse::Unhandled;
  }
  if (te.empty() && !has_length)
    return Refuse(res, ApiErrorKind::kLengthRequired, "length_required",
                  "a request body needs Content-Length or chunked Transfer-Encoding");
  if (length > max_body)
    return Refuse(res, ApiErrorKind::kTooLarge, "too_large",
                  "request body is " + std::to_string(length) + " bytes; the limit is " +
                      std::to_string(max_body));
  const std::string type = Lower(Trim(req.get_header_value("Content-Type")));
  if (type.substr(0, type.find(';')) != "application/json")
    return Refuse(res, ApiErrorKind::kUnsupportedMedia, "unsupported_media_type",
                  "Content-Type must be application/json, got '" + type + "'");
  if (req.has_header("Origin")) {
    const std::string origin = Lower(Trim(req.get_header_value("Origin")));
    const std::string own = "http://" + Lower(Trim(req.get_header_value("Host")));
    if (origin != own)
      return Refuse(res, ApiErrorKind::kForbidden, "cross_origin",
                    "Origin '" + origin + "' is not this station (" + own + ")");
  }
  return httplib::Server::HandlerResponse::Unhandled;
}

}  // namespace

void Route(httplib::Server& s, ApiContext& c, const std::string& method, const std::string& pattern,
           RouteHandler handler, std::size_t max_body_bytes) {
  c.routes.push_back({method, std::regex(pattern), max_body_bytes});
  if (method == "GET") {
    s.Get(pattern, [&c, handler](const httplib::Request& req, httplib::Response& res) {
      handler(c, req, res);
    });
    return;
  }
  httplib::Server::HandlerWithContentReader read_then_handle =
      [&c, handler, max_body_bytes](const httplib::Request& req, httplib::Response& res,
                                    const httplib::ContentReader& read) {
        std::string body;
        bool too_large = false;
        const bool ok = read([&](const char* data, std::size_t n) {
          if (body.size() + n > max_body_bytes) {
            too_large = true;
            return false;
          }
          body.append(data, n);
          return true;
        });
        if (too_large || !ok) {
          CloseAfterResponse();
          return Send(res, too_large ? ApiError{ApiErrorKind::kTooLarge, "too_large",
                                                "request body exceeds the limit of " +
                                                    std::to_string(max_body_bytes) + " bytes"}
                                     : ApiError{ApiErrorKind::kBadRequest, "bad_body",
                                                "the request body ended early or its chunked "
                                                "framing is malformed"});
        }
        httplib::Request with_body = req;
        with_body.body = std::move(body);
        handler(c, with_body, res);
      };
  if (method == "POST") {
    s.Post(pattern, std::move(read_then_handle));
  } else if (method == "PUT") {
    s.Put(pattern, std::move(read_then_handle));
  } else {
    throw std::logic_error("http: no route binding for method " + method);
  }
}

void InstallGate(ApiServer& s, ApiContext& c) {
  // No page of this station may be framed by another (clickjacking).
  s.set_default_headers(
      {{"Content-Security-Policy", "frame-ancestors 'none'"}, {"X-Frame-Options", "DENY"}});
  s.set_pre_routing_handler(
      [&c](const httplib::Request& req, httplib::Response& res) { return Check(c, req, res); });
  // httplib's own refusals (a malformed request line, a URI too long) carry no body.
  s.set_error_handler(
      httplib::Server::HandlerWithResponse([](const httplib::Request&, httplib::Response& res) {
        if (!res.body.empty()) return httplib::Server::HandlerResponse::Unhandled;
        Send(res, HttpReply{res.status,
                            {{"error",
                              {{"code", "http_" + std::to_string(res.status)},
                               {"message", "the HTTP layer refused the request (status " +
                                               std::to_string(res.status) + ")"}}}}});
        return httplib::Server::HandlerResponse::Handled;
      }));
}

}  // namespace eol::station::http
