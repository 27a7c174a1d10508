// The station's Prometheus metrics (GET /metrics) for a plant's Grafana, kept in
// prometheus-cpp's registry and written by its text serializer (exposition format 0.0.4).
//
// Families (units in the names, Prometheus conventions):
//   eol_tests_total{outcome,reason}        counter  finished tests; reason = code of the first
//                                                    reason ("none" for a clean PASS)
//   eol_cycle_seconds                      histogram serial received -> verdict published
//   eol_step_seconds{step}                 histogram one step of the cycle (cycle_time.h)
//   eol_station_overhead_seconds           histogram cycle minus clamp, excitation, unclamp
//   eol_fixture_errors_total               counter  fixture calls that failed (communication)
//   eol_watchdog_trips_total               counter  interlock watchdog cut the excitation
//   eol_stuck_tests_total                  counter  tests past their deadline (systemd restarts)
//   eol_testing, eol_ready, eol_lockout, eol_simulation      gauges 0/1
//   eol_queue_length                       gauge    serials waiting
//   eol_disk_free_bytes, eol_db_size_bytes gauges   of the database's file system and files
//   eol_central_backlog_records            gauge    stored records not yet in the central
//                                                    PostgreSQL record (absent without one)
//   eol_central_connected                  gauge    0/1, the replicator's last attempt worked
//   eol_last_resonance_hz                  gauge    resonance of the last unit (absent before)
//   eol_info{station_id,recipe_id,recipe_hash,software_version}  gauge 1
// Thread-safe: tests are counted from the sequencer's thread while the API scrapes.
#pragma once

#include <prometheus/counter.h>
#include <prometheus/family.h>
#include <prometheus/gauge.h>
#include <prometheus/histogram.h>
#include <prometheus/registry.h>

#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "db/test_record.h"

namespace eol::station {

// What is read at scrape time (the rest is counted as it happens).
struct LiveMetrics {
  bool testing = false;
  bool ready = false;
  bool locked_out = false;
  bool simulation = false;
  std::size_t queue_length = 0;
  std::uint64_t fixture_errors = 0;             // cumulative (drivers::Fixture::failures)
  std::uint64_t watchdog_trips = 0;             // cumulative (Sequencer::watchdog_trips)
  std::string db_path;                          // disk free and size from here ("" : not reported)
  std::optional<std::int64_t> central_backlog;  // with a central record (Station::StartCentral)
  bool central_connected = false;
  std::string station_id, recipe_id, recipe_hash, software_version;
};

class StationMetrics {
 public:
  StationMetrics();
  StationMetrics(const StationMetrics&) = delete;
  StationMetrics& operator=(const StationMetrics&) = delete;

  // A test has ended (the record RunTest returned, with its full cycle_s).
  void OnTest(const db::TestRecord& record);
  void OnStuckTest();
  // The exposition text of every family, with the live values.
  std::string Render(const LiveMetrics& live);

 private:
  std::mutex mu_;
  std::shared_ptr<prometheus::Registry> registry_;
  prometheus::Family<prometheus::Counter>& tests_;
  prometheus::Histogram& cycle_;
  prometheus::Family<prometheus::Histogram>& steps_;
  prometheus::Histogram& overhead_;
  prometheus::Counter& fixture_errors_;
  prometheus::Counter& watchdog_trips_;
  prometheus::Counter& stuck_;
  prometheus::Gauge& testing_;
  prometheus::Gauge& ready_;
  prometheus::Gauge& lockout_;
  prometheus::Gauge& simulation_;
  prometheus::Gauge& queue_;
  prometheus::Gauge& disk_free_;
  prometheus::Gauge& db_size_;
  prometheus::Family<prometheus::Gauge>& central_backlog_;
  prometheus::Family<prometheus::Gauge>& central_connected_;
  prometheus::Family<prometheus::Gauge>& last_resonance_;
  prometheus::Family<prometheus::Gauge>& info_;
  prometheus::Gauge* info_gauge_ = nullptr;  // the label set shown now
  std::uint64_t fixture_errors_seen_ = 0;
  std::uint64_t watchdog_trips_seen_ = 0;
};

}  // namespace eol::station
