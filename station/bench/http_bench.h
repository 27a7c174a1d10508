// Capacity benchmark of the station's HTTP API (issue 14): the latency of GET /api/status
// while `streams` event streams stay open, `slow` slow connections dribble request heads
// and `clients` clients poll at once, and the
// process's peak memory while one client sends a chunked body of `chunked_bytes` to
// POST /api/tests. The API is the daemon's (HttpApi on the real server and gate, a real SQLite
// store), in this process on 127.0.0.1; the clients are threads of the same process, so the
// memory figure is an upper bound for the server.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

namespace eol::station {

struct HttpBenchOptions {
  int streams = 100;  // open GET /api/events connections during the poll
  int clients = 200;  // concurrent pollers of GET /api/status, one request each at a time
  int slow = 0;       // slow connections during the poll: a request head, one byte every 500 ms,
                      // reconnecting when the server cuts one off
  double seconds = 10.0;                             // duration of the poll
  std::size_t chunked_bytes = std::size_t{1} << 30;  // the chunked body offered (1 GiB)
};

struct HttpBenchResult {
  int streams_requested = 0, streams_open = 0;
  int slow_requested = 0;
  long slow_connects = 0;  // connections the slow clients opened (first ones and reconnects)
  long requests = 0;       // GET /api/status answered 200
  long refused = 0;        // answered 503 (the server's stated overload answer)
  long failed = 0;         // no answer or another status
  double p50_ms = 0, p90_ms = 0, p99_ms = 0, max_ms = 0;
  int chunked_status = 0;                       // what the server answered the chunked body
  std::size_t chunked_sent_bytes = 0;           // what the client got to send before the answer
  double rss_before_mib = 0, rss_peak_mib = 0;  // VmRSS before, VmHWM after the chunked body
};

HttpBenchResult RunHttpBench(const HttpBenchOptions& options);
nlohmann::json ToJson(const HttpBenchResult& r);

}  // namespace eol::station
