// What every route handler works with: the board, the options, the station's handlers and
// the API's own read connection to the store. Internal to station/daemon/http; HttpApi owns one.
#pragma once

#include <functional>
#include <memory>
#include <mutex>
#include <regex>
#include <string>
#include <vector>

#include "db/store.h"
#include "station/daemon/http/request.h"
#include "station/daemon/http_api.h"

namespace httplib {
class Server;
struct Request;
struct Response;
}  // namespace httplib

namespace eol::station::http {

struct ApiContext {
  ApiContext(StatusBoard& b, HttpOptions o, HttpHandlers h)
      : board(b), options(std::move(o)), handlers(std::move(h)) {}

  StatusBoard& board;
  const HttpOptions options;
  const HttpHandlers handlers;
  // One request at a time reads through `db`; it never recovers unfinished tests.
  std::mutex db_mu;
  std::unique_ptr<db::Store> db;
  // Every route as registered (method, path pattern): the gate answers 404 and 405 from it.
  struct RouteEntry {
    std::string method;
    std::regex pattern;
    std::size_t max_body_bytes = 0;  // POST and PUT
  };
  std::vector<RouteEntry> routes;
};

// A route handler: one function per route, grouped by resource in station/daemon/http/*_routes.cc.
using RouteHandler = void (*)(ApiContext&, const httplib::Request&, httplib::Response&);

// Registers `handler` for `method` ("GET", "POST" or "PUT") and `pattern` on the server and
// in c.routes. POST and PUT bodies are read through httplib's content reader, so that a body
// of any framing (Content-Length or chunked) stops at `max_body_bytes` (413, nothing more is
// buffered; the gate refuses a larger Content-Length unread); the handler then finds it in
// req.body. The server's own cap (HttpApi) is the largest route's.
void Route(httplib::Server& s, ApiContext& c, const std::string& method, const std::string& pattern,
           RouteHandler handler, std::size_t max_body_bytes = kMaxBodyBytes);

}  // namespace eol::station::http
