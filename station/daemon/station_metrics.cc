#include "station/daemon/station_metrics.h"

#include <prometheus/text_serializer.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <system_error>

#include "analysis/qc/measurement_names.h"
#include "station/daemon/cycle_time.h"

namespace eol::station {
namespace {

// Seconds: from a few milliseconds (store, judge) to the clamp and excitation's seconds.
const prometheus::Histogram::BucketBoundaries kSecondsBuckets = {
    0.001, 0.0025, 0.005, 0.01, 0.025, 0.05, 0.1, 0.25, 0.5,
    0.75,  1.0,    1.5,   2.0,  3.0,   5.0,  7.5, 10.0, 20.0};

std::uint64_t FileSize(const std::filesystem::path& p) {
  std::error_code ec;
  const auto n = std::filesystem::file_size(p, ec);
  return ec ? 0 : n;
}

prometheus::Gauge& Gauge(prometheus::Registry& r, const char* name, const char* help) {
  return prometheus::BuildGauge().Name(name).Help(help).Register(r).Add({});
}

}  // namespace

StationMetrics::StationMetrics()
    : registry_(std::make_shared<prometheus::Registry>()),
      tests_(prometheus::BuildCounter()
                 .Name("eol_tests_total")
                 .Help("Finished tests since the station started, by outcome and reason code.")
                 .Register(*registry_)),
      cycle_(prometheus::BuildHistogram()
                 .Name("eol_cycle_seconds")
                 .Help("Serial received to verdict published.")
                 .Register(*registry_)
                 .Add({}, kSecondsBuckets)),
      steps_(prometheus::BuildHistogram()
                 .Name("eol_step_seconds")
                 .Help("Duration of one step of the test cycle (interlocks, clamp, excitation, "
                       "analysis, judge, unclamp, safe_state, store, publish).")
                 .Register(*registry_)),
      overhead_(prometheus::BuildHistogram()
                    .Name("eol_station_overhead_seconds")
                    .Help("Cycle time not spent on clamp motion or excitation.")
                    .Register(*registry_)
                    .Add({}, kSecondsBuckets)),
      fixture_errors_(prometheus::BuildCounter()
                          .Name("eol_fixture_errors_total")
                          .Help("Fixture calls that failed (communication or refused command).")
                          .Register(*registry_)
                          .Add({})),
      watchdog_trips_(prometheus::BuildCounter()
                          .Name("eol_watchdog_trips_total")
                          .Help("Times the interlock watchdog cut the excitation.")
                          .Register(*registry_)
                          .Add({})),
      stuck_(prometheus::BuildCounter()
                 .Name("eol_stuck_tests_total")
                 .Help("Tests past their deadline (systemd's watchdog restarts the daemon).")
                 .Register(*registry_)
                 .Add({})),
      testing_(Gauge(*registry_, "eol_testing", "1 while a test is in progress.")),
      ready_(Gauge(*registry_, "eol_ready", "1 when the fixture and the DAQ answered.")),
      lockout_(Gauge(*registry_, "eol_lockout", "1 while a self-check lockout refuses tests.")),
      simulation_(Gauge(*registry_, "eol_simulation", "1 when the station runs on simulators.")),
      queue_(Gauge(*registry_, "eol_queue_length", "Serials waiting to be tested.")),
      disk_free_(Gauge(*registry_, "eol_disk_free_bytes",
                       "Free space of the file system holding the database.")),
      db_size_(Gauge(*registry_, "eol_db_size_bytes",
                     "Size of the database files (main, WAL, shared memory).")),
      central_backlog_(prometheus::BuildGauge()
                           .Name("eol_central_backlog_records")
                           .Help("Stored records not yet in the central PostgreSQL record.")
                           .Register(*registry_)),
      central_connected_(prometheus::BuildGauge()
                             .Name("eol_central_connected")
                             .Help("1 when the last attempt to replicate to the central "
                                   "record worked.")
                             .Register(*registry_)),
      last_resonance_(prometheus::BuildGauge()
                          .Name("eol_last_resonance_hz")
                          .Help("Resonance of the last tested unit.")
                          .Register(*registry_)),
      info_(prometheus::BuildGauge()
                .Name("eol_info")
                .Help("The station's identity: 1, with its labels.")
                .Register(*registry_)) {}

void StationMetrics::OnTest(const db::TestRecord& record) {
  std::lock_guard<std::mutex> lock(mu_);
  const std::string reason =
      record.reasons.empty() ? "none" : analysis::ToString(record.reasons.front().code);
  std::string outcome = analysis::ToString(record.outcome);
  for (char& c : outcome) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  tests_.Add({{"outcome", outcome}, {"reason", reason}}).Increment();
  for (const auto& [step, s] : record.cycle_s) {
    if (step == "total") continue;
    steps_.Add({{"step", step}}, kSecondsBuckets).Observe(s);
  }
  if (const auto it = record.cycle_s.find("total"); it != record.cycle_s.end()) {
    cycle_.Observe(it->second);
    overhead_.Observe(StationOverheadS(record.cycle_s));
  }
  for (const auto& m : record.measurements)
    if (m.name == analysis::names::kResonanceFHz && std::isfinite(m.value))
      last_resonance_.Add({}).Set(m.value);
}

void StationMetrics::OnStuckTest() { stuck_.Increment(); }

std::string StationMetrics::Render(const LiveMetrics& live) {
  std::lock_guard<std::mutex> lock(mu_);
  testing_.Set(live.testing ? 1 : 0);
  ready_.Set(live.ready ? 1 : 0);
  lockout_.Set(live.locked_out ? 1 : 0);
  simulation_.Set(live.simulation ? 1 : 0);
  queue_.Set(static_cast<double>(live.queue_length));
  // Cumulative counts kept by the drivers and the sequencer: counted here as they grow.
  if (live.fixture_errors > fixture_errors_seen_)
    fixture_errors_.Increment(static_cast<double>(live.fixture_errors - fixture_errors_seen_));
  fixture_errors_seen_ = std::max(fixture_errors_seen_, live.fixture_errors);
  if (live.watchdog_trips > watchdog_trips_seen_)
    watchdog_trips_.Increment(static_cast<double>(live.watchdog_trips - watchdog_trips_seen_));
  watchdog_trips_seen_ = std::max(watchdog_trips_seen_, live.watchdog_trips);
  if (!live.db_path.empty()) {
    const std::filesystem::path db(live.db_path);
    std::error_code ec;
    const auto space = std::filesystem::space(
        db.has_parent_path() ? db.parent_path() : std::filesystem::path("."), ec);
    if (!ec) disk_free_.Set(static_cast<double>(space.available));
    db_size_.Set(static_cast<double>(FileSize(db) + FileSize(live.db_path + "-wal") +
                                     FileSize(live.db_path + "-shm")));
  }
  if (live.central_backlog) {
    central_backlog_.Add({}).Set(static_cast<double>(*live.central_backlog));
    central_connected_.Add({}).Set(live.central_connected ? 1 : 0);
  }
  if (info_gauge_ != nullptr) info_.Remove(info_gauge_);
  info_gauge_ = &info_.Add({{"station_id", live.station_id},
                            {"recipe_id", live.recipe_id},
                            {"recipe_hash", live.recipe_hash},
                            {"software_version", live.software_version}});
  info_gauge_->Set(1);
  std::ostringstream out;
  prometheus::TextSerializer().Serialize(out, registry_->Collect());
  return out.str();
}

}  // namespace eol::station
