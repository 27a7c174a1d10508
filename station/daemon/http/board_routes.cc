// The live station: status, server-sent events, Prometheus metrics, the operator page and the
// engineer page.
#include <fstream>
#include <sstream>

#include "station/daemon/http/routes.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include "station/daemon/http/server.h"

namespace eol::station::http {
namespace {

void GetStatus(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  nlohmann::json status = c.board.Snapshot();
  status["language"] = c.options.language;  // the operator page's (station config "language")
  Send(res, HttpReply{200, std::move(status)});
}

void GetEvents(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  // A stream holds its connection for as long as the page is open: its thread leaves the
  // request workers (station/daemon/http/server.h), up to a maximum of streams.
  if (!BecomeStream())
    return Send(
        res, ApiError{ApiErrorKind::kUnavailable, "too_many_streams",
                      "the station serves at most " + std::to_string(c.options.limits.max_streams) +
                          " event streams at once; close one (another tab?)"});
  auto last = std::make_shared<std::uint64_t>(c.board.last_event());
  auto opened = std::make_shared<bool>(false);
  res.set_header("Cache-Control", "no-cache");
  res.set_chunked_content_provider(
      "text/event-stream", [&c, last, opened](std::size_t, httplib::DataSink& sink) {
        if (!*opened) {  // a browser reconnects 1 s after losing the stream (default: 3 s)
          *opened = true;
          const std::string retry = "retry: 1000\n\n";
          if (!sink.write(retry.data(), retry.size())) return false;
        }
        // A quiet half second is a "ping" event: the page calls the station offline when
        // nothing at all arrived for 1.5 s (station/web/app.js), and a proxy keeps the stream.
        const auto events = c.board.EventsAfter(*last, std::chrono::milliseconds(500));
        if (events.empty()) {
          const std::string ping = "event: ping\ndata: {}\n\n";
          return sink.write(ping.data(), ping.size());
        }
        for (const auto& [seq, e] : events) {
          const std::string msg = "id: " + std::to_string(seq) +
                                  "\nevent: " + e.value("type", "message") + "\ndata: " + e.dump() +
                                  "\n\n";
          if (!sink.write(msg.data(), msg.size())) return false;
          *last = seq;
        }
        return true;
      });
}

void GetMetrics(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  if (!c.handlers.metrics)
    return Send(res, ApiError{ApiErrorKind::kUnavailable, "no_metrics",
                              "this server has no station behind it to measure"});
  res.set_content(c.handlers.metrics(), "text/plain; version=0.0.4");
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A page of the web root, or a short page that says it is not installed.
void SendPage(const ApiContext& c, const std::string& file, const std::string& what,
              httplib::Response& res) {
  std::string page;
  if (!c.options.web_root.empty()) page = ReadFile(c.options.web_root + "/" + file);
  if (page.empty())
    page =
        "<!doctype html><html lang=\"en\"><title>EOL station</title><h1>EOL station</h1>"
        "<p>The " +
        what + " is not installed; see <a href=\"/api/status\">/api/status</a>.";
  res.set_content(page, "text/html; charset=utf-8");
}

void GetOperatorPage(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  SendPage(c, "index.html", "operator page", res);
}

void GetEngineerPage(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  SendPage(c, "engineer.html", "engineer page", res);
}

}  // namespace

void AddBoardRoutes(httplib::Server& s, ApiContext& c) {
  Route(s, c, "GET", "/api/status", GetStatus);
  Route(s, c, "GET", "/api/events", GetEvents);
  Route(s, c, "GET", "/metrics", GetMetrics);
  Route(s, c, "GET", "/", GetOperatorPage);
  Route(s, c, "GET", "/engineer", GetEngineerPage);
  if (!c.options.web_root.empty()) s.set_mount_point("/static", c.options.web_root);
}

}  // namespace eol::station::http
