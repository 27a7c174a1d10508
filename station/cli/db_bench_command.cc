// `eol db-bench`: a generated store at a line's scale (station/bench/db_bench.h): bytes per
// test, growth per year, per-serial lookups and one day's export.
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "station/bench/db_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/progress.h"

namespace eol::station::cli {
namespace {

struct DbBenchArgs {
  DbBenchOptions o;
  bool json = false;
};

int RunDbBenchCommand(DbBenchArgs& a) {
  DbBenchSummary s;
  {
    Progress progress("db-bench");
    a.o.progress = progress.Callback();
    s = RunDbBench(a.o);
  }
  if (a.json) {
    std::cout << nlohmann::json{{"tests", s.tests},
                                {"generated", s.generated},
                                {"replicate_s", s.replicate_s},
                                {"template_serial", s.template_serial},
                                {"insert_s", s.insert_s},
                                {"file_bytes", s.file_bytes},
                                {"bytes_per_test", s.bytes_per_test},
                                {"growth_gb_per_year", s.growth_gb_per_year},
                                {"history_median_ms", s.history_median_ms},
                                {"history_p99_ms", s.history_p99_ms},
                                {"latest_median_ms", s.latest_median_ms},
                                {"latest_p99_ms", s.latest_p99_ms},
                                {"day_tests", s.day_tests},
                                {"day_export_s", s.day_export_s},
                                {"day_export_curves_s", s.day_export_curves_s},
                                {"day_measurement_rows", s.day_measurement_rows},
                                {"day_measurements_s", s.day_measurements_s},
                                {"open_read_only_s", s.open_read_only_s},
                                {"open_writer_s", s.open_writer_s},
                                {"finish_median_ms", s.finish_median_ms},
                                {"finish_p99_ms", s.finish_p99_ms},
                                {"finish_no_checkpoint_median_ms",
                                 s.finish_no_checkpoint_median_ms},
                                {"finish_no_checkpoint_p99_ms", s.finish_no_checkpoint_p99_ms}}
                     .dump(2)
              << std::endl;
    return 0;
  }
  std::printf("%lld tests from the record of %s, generated in %.1f s (%.0f tests/s)\n",
              static_cast<long long>(s.generated), s.template_serial.c_str(), s.insert_s,
              static_cast<double>(s.generated) / s.insert_s);
  if (s.tests > s.generated)
    std::printf("copied in SQLite to %d blocks, %lld tests in %.1f s (%.0f tests/s)\n",
                a.o.replicate, static_cast<long long>(s.tests), s.replicate_s,
                static_cast<double>(s.tests - s.generated) / s.replicate_s);
  std::printf("file %.2f GB: %.0f bytes per test, %.2f GB per year at one test per %.0f s\n",
              s.file_bytes / 1e9, s.bytes_per_test, s.growth_gb_per_year, a.o.interval_s);
  std::printf(
      "history of a serial: median %.3f ms, p99 %.3f ms; newest test with curves: "
      "median %.3f ms, p99 %.3f ms (%d random serials)\n",
      s.history_median_ms, s.history_p99_ms, s.latest_median_ms, s.latest_p99_ms, a.o.queries);
  std::printf(
      "one day (%lld tests): export %.2f s, with curves %.2f s; %lld measurement rows "
      "in %.2f s\n",
      static_cast<long long>(s.day_tests), s.day_export_s, s.day_export_curves_s,
      static_cast<long long>(s.day_measurement_rows), s.day_measurements_s);
  std::printf("open with PRAGMA quick_check: read-only %.2f s, as the station's writer %.2f s\n",
              s.open_read_only_s, s.open_writer_s);
  std::printf(
      "finish a test (BeginTest + FinishTest): median %.2f ms, p99 %.2f ms with the checkpoint "
      "after each verdict; median %.2f ms, p99 %.2f ms without (%d tests each)\n",
      s.finish_median_ms, s.finish_p99_ms, s.finish_no_checkpoint_median_ms,
      s.finish_no_checkpoint_p99_ms, a.o.finish_samples);
  return 0;
}

}  // namespace

void AddDbBenchCommand(CLI::App& app) {
  auto args = std::make_shared<DbBenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "db-bench",
      "Generate a store of N tests from a station store's newest record (its curves and\n"
      "measurements perturbed per test, one test per --interval-s, some retests) and measure\n"
      "on it what eol query and eol export do: a serial's history, its newest test with\n"
      "curves, one day's export; prints bytes per test and the growth per year.\n"
      "Exit: 0 measured, 2 usage, file or store error (an existing --db included).");
  cmd->add_option("--db", args->o.db, "Store to create (must not exist)")->required();
  cmd->add_option("--template", args->o.template_db,
                  "Station store whose newest test is the template (e.g. from eol demo)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--tests", args->o.tests, "Tests to generate")->check(Between(1, 1e8));
  cmd->add_option("--batch", args->o.batch, "Tests per transaction")->check(Between(1, 1000000));
  cmd->add_option("--interval-s", args->o.interval_s, "Seconds between tests on the line")
      ->check(Positive());
  cmd->add_option("--retest-share", args->o.retest_share, "Share of tests that are retests")
      ->check(Between(0.0, 0.99));
  cmd->add_option("--queries", args->o.queries, "Random serials looked up")
      ->check(Between(1, 1000000));
  cmd->add_option("--seed", args->o.seed, "Seed of the perturbations and lookups");
  cmd->add_option("--replicate", args->o.replicate,
                  "Copies of the generated block in the store, made inside SQLite (later in "
                  "time, new serials, the same bytes): --tests 100000 --replicate 50 measures "
                  "5 million tests")
      ->check(Between(1, 10000));
  cmd->add_option("--finish-samples", args->o.finish_samples,
                  "Tests finished one at a time with and without the checkpoint")
      ->capture_default_str()
      ->check(Between(1, 100000));
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("db-bench", [&] { return RunDbBenchCommand(*args); }); });
}

}  // namespace eol::station::cli
