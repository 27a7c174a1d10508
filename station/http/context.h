// What every route handler works with: the board, the options, the station's handlers and
// the API's own read connection to the store. Internal to station/http; HttpApi owns one.
#pragma once

#include <functional>
#include <memory>
#include <mutex>

#include "db/store.h"
#include "station/http_api.h"

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
};

// A route handler: one function per route, grouped by resource in station/http/*_routes.cc.
using RouteHandler = void (*)(ApiContext&, const httplib::Request&, httplib::Response&);

// The route's handler as httplib::Server::Handler.
inline std::function<void(const httplib::Request&, httplib::Response&)> Bind(ApiContext& c,
                                                                             RouteHandler h) {
  return [&c, h](const httplib::Request& req, httplib::Response& res) { h(c, req, res); };
}

}  // namespace eol::station::http
