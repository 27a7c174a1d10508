// The live station: status, server-sent events, Prometheus metrics and the operator page.
#include <fstream>
#include <sstream>

#include "station/http/routes.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station::http {
namespace {

void GetStatus(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  Send(res, HttpReply{200, c.board.Snapshot()});
}

void GetEvents(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  auto last = std::make_shared<std::uint64_t>(c.board.last_event());
  res.set_header("Cache-Control", "no-cache");
  res.set_chunked_content_provider(
      "text/event-stream", [&c, last](std::size_t, httplib::DataSink& sink) {
        const auto events = c.board.EventsAfter(*last, std::chrono::milliseconds(1000));
        if (events.empty()) {
          const std::string ping = ": keep-alive\n\n";
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
  const nlohmann::json st = c.board.Snapshot();
  std::ostringstream m;
  m << "# HELP eol_tests_total Finished tests since the station started, by outcome.\n"
    << "# TYPE eol_tests_total counter\n";
  for (const char* o : {"pass", "fail", "error", "aborted"})
    m << "eol_tests_total{outcome=\"" << o << "\"} " << st["counts"][o].get<std::uint64_t>()
      << "\n";
  m << "# HELP eol_testing 1 while a test is in progress.\n# TYPE eol_testing gauge\n"
    << "eol_testing " << (st["state"] == "wait_serial" || st["state"] == "idle" ? 0 : 1) << "\n";
  if (st["last"].is_object()) {
    for (const auto& meas : st["last"]["measurements"]) {
      if (meas["name"] != "resonance_f_hz" || !meas["value"].is_number()) continue;
      m << "# HELP eol_last_resonance_hz Resonance of the last tested unit.\n"
        << "# TYPE eol_last_resonance_hz gauge\n"
        << "eol_last_resonance_hz " << meas["value"].get<double>() << "\n";
    }
  }
  res.set_content(m.str(), "text/plain; version=0.0.4");
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void GetOperatorPage(ApiContext& c, const httplib::Request&, httplib::Response& res) {
  std::string page;
  if (!c.options.web_root.empty()) page = ReadFile(c.options.web_root + "/index.html");
  if (page.empty())
    page =
        "<!doctype html><title>EOL station</title><h1>EOL station</h1>"
        "<p>The operator page is not installed; see <a href=\"/api/status\">/api/status</a>.";
  res.set_content(page, "text/html; charset=utf-8");
}

}  // namespace

void AddBoardRoutes(httplib::Server& s, ApiContext& c) {
  s.Get("/api/status", Bind(c, GetStatus));
  s.Get("/api/events", Bind(c, GetEvents));
  s.Get("/metrics", Bind(c, GetMetrics));
  s.Get("/", Bind(c, GetOperatorPage));
  if (!c.options.web_root.empty()) s.set_mount_point("/static", c.options.web_root);
}

}  // namespace eol::station::http
