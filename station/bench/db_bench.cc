#include "station/bench/db_bench.h"

#include <sqlite3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <tuple>
#include <vector>

#include "db/clock.h"
#include "db/last_verdict.h"
#include "db/store.h"
#include "station/bench/db_replicate.h"

namespace eol::station {
namespace {

using Clock = std::chrono::steady_clock;

double Seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

// Median and 99th percentile of `ms` (sorted in place).
std::pair<double, double> MedianP99(std::vector<double>& ms) {
  if (ms.empty()) return {0.0, 0.0};
  std::sort(ms.begin(), ms.end());
  const auto at = [&](double q) {
    return ms[std::min(ms.size() - 1,
                       static_cast<std::size_t>(q * static_cast<double>(ms.size())))];
  };
  return {at(0.5), at(0.99)};
}

db::TestRecord Template(const std::string& path) {
  auto store = db::Store::Open(path, db::Store::Role::kReadOnly);
  db::TestQuery q;
  q.limit = 1;
  const std::vector<db::TestRecord> newest = store->Tests(q);
  if (newest.empty()) throw std::runtime_error(path + ": has no finished test to use as template");
  std::optional<db::TestRecord> r = store->Test(newest.front().id, /*with_curves=*/true);
  if (!r) throw std::runtime_error(path + ": the newest test could not be read");
  return *r;
}

// 5. What opening the store and finishing a test cost at this size (db_bench.h).
void MeasureGuards(const DbBenchOptions& o, const db::TestRecord& tmpl, DbBenchSummary& s) {
  const auto open_start = Clock::now();
  (void)db::Store::Open(o.db);
  s.open_writer_s = Seconds(open_start);
  for (const bool checkpoint : {true, false}) {
    db::OpenOptions options;
    options.checkpoint_each_test = checkpoint;
    auto writer = db::Store::Open(o.db, db::Store::Role::kWriter, options);
    std::vector<double> ms;
    for (int i = 0; i < o.finish_samples; ++i) {
      db::TestRecord r = tmpl;
      r.id = 0;
      r.retest_of.reset();
      r.serial = "GUARD-" + std::string(checkpoint ? "C" : "N") + std::to_string(i);
      r.started_at = db::UtcNowIso8601();
      const auto t = Clock::now();
      writer->BeginTest(r);
      r.finished_at = db::UtcNowIso8601();
      writer->FinishTest(r);
      ms.push_back(1e3 * Seconds(t));
    }
    std::tie(checkpoint ? s.finish_median_ms : s.finish_no_checkpoint_median_ms,
             checkpoint ? s.finish_p99_ms : s.finish_no_checkpoint_p99_ms) = MedianP99(ms);
  }
  // The store keeps only the generated tests (their rows cascade with them).
  sqlite3* raw = nullptr;
  const int rc = sqlite3_open_v2(o.db.c_str(), &raw, SQLITE_OPEN_READWRITE, nullptr);
  const bool removed =
      rc == SQLITE_OK && sqlite3_exec(raw,
                                      "PRAGMA foreign_keys = ON; DELETE FROM outbox WHERE test_id "
                                      "IN (SELECT id FROM tests WHERE serial LIKE 'GUARD-%'); "
                                      "DELETE FROM tests WHERE serial LIKE 'GUARD-%'",
                                      nullptr, nullptr, nullptr) == SQLITE_OK;
  const std::string why = raw != nullptr ? sqlite3_errmsg(raw) : "cannot open";
  sqlite3_close(raw);
  if (!removed) throw std::runtime_error(o.db + ": removing the GUARD- tests: " + why);
  std::filesystem::remove(db::LastVerdictPath(o.db));
}

}  // namespace

DbBenchSummary RunDbBench(const DbBenchOptions& o) {
  if (o.tests < 1 || o.batch < 1 || !(o.interval_s > 0.0) || o.queries < 1 || o.replicate < 1 ||
      !(o.retest_share >= 0.0 && o.retest_share < 1.0))
    throw std::runtime_error(
        "db-bench: tests, batch, queries and replicate must be positive, interval_s positive "
        "and retest_share in [0, 1)");
  if (std::filesystem::exists(o.db))
    throw std::runtime_error(o.db +
                             " exists: db-bench creates its own store (choose another --db)");
  const db::TestRecord tmpl = Template(o.template_db);
  DbBenchSummary s;
  s.template_serial = tmpl.serial;

  // 1. Generation.
  const auto t0 = std::chrono::sys_days{std::chrono::year{2026} / 1 / 1};
  const auto step = std::chrono::duration_cast<std::chrono::system_clock::duration>(
      std::chrono::duration<double>(o.interval_s));
  std::mt19937_64 rng(o.seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uniform;
  std::int64_t unit = 0;
  {
    auto store = db::Store::Open(o.db);
    const auto start = Clock::now();
    std::vector<db::TestRecord> batch;
    batch.reserve(static_cast<std::size_t>(o.batch));
    for (std::int64_t i = 0; i < o.tests; ++i) {
      db::TestRecord r = tmpl;
      r.id = 0;
      r.retest_of.reset();
      const bool retest = i > 0 && uniform(rng) < o.retest_share;
      if (!retest) ++unit;
      r.serial = DbBenchSerial(unit);
      const auto at = std::chrono::system_clock::time_point(t0) + i * step;
      r.started_at = db::UtcIso8601(at);
      r.finished_at = db::UtcIso8601(at + std::chrono::milliseconds(850));
      for (analysis::Measurement& m : r.measurements) m.value *= 1.0 + 1e-3 * gauss(rng);
      // Each line moved by its sigma (by 1e-6 of itself without one), as unit to unit.
      for (db::Curve& c : r.curves)
        for (std::size_t k = 0; k < c.re.size(); ++k) {
          c.re[k] += (c.sigma.empty() ? 1e-6 * std::abs(c.re[k]) : c.sigma[k]) * gauss(rng);
          c.im[k] += (c.sigma.empty() ? 1e-6 * std::abs(c.im[k]) : c.sigma[k]) * gauss(rng);
        }
      batch.push_back(std::move(r));
      if (static_cast<int>(batch.size()) == o.batch || i + 1 == o.tests) {
        store->InsertAll(batch);
        batch.clear();
        if (o.progress) o.progress("generate", i + 1, o.tests);
      }
    }
    s.insert_s = Seconds(start);
  }
  s.generated = o.tests;
  const auto copy_start = Clock::now();
  ReplicateBlock(o.db, o.tests, unit, static_cast<double>(o.tests) * o.interval_s, o.replicate,
                 o.progress);
  s.replicate_s = Seconds(copy_start);
  s.tests = o.tests * o.replicate;

  // 2. Size: the database file (closing the writer checkpointed the WAL into it).
  const auto open_start = Clock::now();
  auto store = db::Store::Open(o.db, db::Store::Role::kReadOnly);
  s.open_read_only_s = Seconds(open_start);
  s.file_bytes = static_cast<double>(std::filesystem::file_size(o.db));
  if (std::filesystem::exists(o.db + "-wal"))
    s.file_bytes += static_cast<double>(std::filesystem::file_size(o.db + "-wal"));
  s.bytes_per_test = s.file_bytes / static_cast<double>(s.tests);
  s.growth_gb_per_year = s.bytes_per_test * (365.25 * 86400.0 / o.interval_s) / 1e9;

  // 3. Per-serial lookups.
  std::vector<double> history, latest;
  std::uniform_int_distribution<std::int64_t> pick_unit(1, unit);
  std::uniform_int_distribution<int> pick_copy(0, o.replicate - 1);
  for (int q = 0; q < o.queries; ++q) {
    const std::string serial = DbBenchSerial(pick_unit(rng) + pick_copy(rng) * unit);
    auto t = Clock::now();
    if (store->TestsOfSerial(serial).empty()) throw std::runtime_error("lost serial " + serial);
    history.push_back(1e3 * Seconds(t));
    t = Clock::now();
    if (!store->LatestOfSerial(serial)) throw std::runtime_error("lost serial " + serial);
    latest.push_back(1e3 * Seconds(t));
    if (o.progress && (q + 1) % 100 == 0) o.progress("lookups", q + 1, o.queries);
  }
  std::tie(s.history_median_ms, s.history_p99_ms) = MedianP99(history);
  std::tie(s.latest_median_ms, s.latest_p99_ms) = MedianP99(latest);

  // 4. One day's export (the middle day of the generated span), as eol export pages it.
  const std::int64_t per_day = static_cast<std::int64_t>(86400.0 / o.interval_s);
  const std::int64_t day = std::max<std::int64_t>(0, (s.tests / per_day) / 2);
  const auto day_start = std::chrono::system_clock::time_point(t0) + std::chrono::days(day);
  for (bool curves : {false, true}) {
    db::TestQuery q;
    q.from = db::UtcIso8601(day_start);
    q.to = db::UtcIso8601(day_start + std::chrono::days(1));
    q.limit = 10000;
    q.with_curves = curves;
    std::int64_t rows = 0;
    const auto t = Clock::now();
    for (;;) {
      const std::vector<db::TestRecord> page = store->Tests(q);
      rows += static_cast<std::int64_t>(page.size());
      if (static_cast<int>(page.size()) < q.limit) break;
      q.after = std::make_pair(page.back().started_at, page.back().id);
    }
    (curves ? s.day_export_curves_s : s.day_export_s) = Seconds(t);
    s.day_tests = rows;
  }
  db::MeasurementQuery mq;
  mq.from = db::UtcIso8601(day_start);
  mq.to = db::UtcIso8601(day_start + std::chrono::days(1));
  const auto t = Clock::now();
  s.day_measurement_rows = static_cast<std::int64_t>(store->MeasurementRows(mq).size());
  s.day_measurements_s = Seconds(t);
  store.reset();
  MeasureGuards(o, tmpl, s);
  return s;
}

}  // namespace eol::station
