// `eol http-bench`: the HTTP API's capacity with many event streams and concurrent clients,
// and its memory under a huge chunked body (station/bench/http_bench.h).
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "station/bench/http_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"

namespace eol::station::cli {

void AddHttpBenchCommand(CLI::App& app) {
  auto o = std::make_shared<HttpBenchOptions>();
  auto json = std::make_shared<bool>(false);
  auto mib = std::make_shared<double>(1024.0);
  CLI::App* cmd = app.add_subcommand(
      "http-bench",
      "Benchmark: latency of GET /api/status with many open event streams and concurrent\n"
      "clients, and peak memory while a client sends a huge chunked body, on the station's\n"
      "HTTP API served in this process on 127.0.0.1.");
  cmd->add_option("--streams", o->streams, "Open event streams")
      ->capture_default_str()
      ->check(Between(0, 1000));
  cmd->add_option("--slow", o->slow,
                  "Slow connections during the poll (a head, a byte every 500 ms)")
      ->capture_default_str()
      ->check(Between(0, 700));
  cmd->add_option("--clients", o->clients, "Concurrent clients polling /api/status")
      ->capture_default_str()
      ->check(Between(1, 1000));
  cmd->add_option("--seconds", o->seconds, "Duration of the poll")
      ->capture_default_str()
      ->check(Between(0.1, 600.0));
  cmd->add_option("--chunked-mib", *mib, "Chunked body offered, MiB")
      ->capture_default_str()
      ->check(Between(1.0, 65536.0));
  cmd->add_flag("--json", *json, "Print the figures as JSON");
  cmd->callback([o, json, mib] {
    RunGuarded("http-bench", [&] {
      spdlog::set_level(spdlog::level::off);
      o->chunked_bytes = static_cast<std::size_t>(*mib * 1024.0 * 1024.0);
      const HttpBenchResult r = RunHttpBench(*o);
      if (*json) {
        std::cout << ToJson(r).dump(2) << std::endl;
        return 0;
      }
      std::printf(
          "chunked body: offered %.0f MiB, sent %.2f MiB, answered %d; memory %.1f MiB "
          "before, peak %.1f MiB\n",
          *mib, static_cast<double>(r.chunked_sent_bytes) / 1048576.0, r.chunked_status,
          r.rss_before_mib, r.rss_peak_mib);
      std::printf(
          "streams open %d of %d; %d slow connections (%ld connects); %d clients for %.1f s: "
          "%ld answered 200, %ld 503, %ld failed\n",
          r.streams_open, r.streams_requested, r.slow_requested, r.slow_connects, o->clients,
          o->seconds, r.requests, r.refused, r.failed);
      std::printf("GET /api/status latency ms: p50 %.2f  p90 %.2f  p99 %.2f  max %.2f\n", r.p50_ms,
                  r.p90_ms, r.p99_ms, r.max_ms);
      return 0;
    });
  });
}

}  // namespace eol::station::cli
