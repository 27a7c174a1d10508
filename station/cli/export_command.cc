// `eol export --db FILE [--serial SN] [--from T] [--to T] [--order NO] [--outcome O]
// [--recipe R]... [--format csv|json|records] [--out FILE]`: tests out of the station for
// quality engineering, one row per test in the export schema (db/export_schema.h: fixed
// columns that never depend on the data), as CSV or JSON; or full records with curves
// (`records`, what `eol teach --golden` reads). `eol export --schema` prints the columns.
#include <fstream>
#include <iostream>
#include <map>
#include <set>

#include "analysis/qc/measurement_names.h"
#include "db/export_schema.h"
#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/progress.h"
#include "station/daemon/judge.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

struct ExportArgs {
  std::string db;
  std::string serial;
  std::string from;
  std::string to;
  std::string order;
  std::string outcome;
  std::vector<std::string> recipes;
  std::string format = "csv";
  std::string out;
  int limit = 10000;
  bool all = false;  // every test, in pages of page_size (keyset paging), memory bounded
  int page_size = 10000;
  bool schema = false;
  bool json = false;  // --json: --format json
};

// What a recipe declares beyond the standard names, in the order it judges them: its limits,
// its masks' line counts, then the same for each further phase pair ("<name>@V-W").
std::vector<std::string> DeclaredBy(const Recipe& r) {
  std::vector<std::string> first;
  for (std::string_view n : analysis::names::kAll) first.emplace_back(n);
  for (const auto& l : r.limits) first.push_back(l.name);
  for (const auto& m : r.masks) first.push_back(m.MeasurementName());
  std::vector<std::string> all = first;
  for (std::size_t k = 1; k < r.phase_pairs.size(); ++k)
    for (const std::string& n : first) all.push_back(n + "@" + PairName(r.phase_pairs[k]));
  return all;
}

int RunExport(ExportArgs a) {
  if (a.json) {
    if (a.format != "csv" && a.format != "json")
      throw std::runtime_error("--json asks for --format json, not " + a.format);
    a.format = "json";
  }
  std::vector<std::string> extra;
  for (const std::string& path : a.recipes)
    for (std::string& n : DeclaredBy(LoadRecipe(path))) extra.push_back(std::move(n));
  const std::vector<db::ExportColumn> columns =
      db::ExportColumns(db::ExportMeasurementNames(extra));
  if (a.schema) {
    std::cout << db::ExportSchemaMarkdown(columns);
    return 0;
  }
  if (a.db.empty()) throw std::runtime_error("--db is required (except with --schema)");

  auto store = db::Store::Open(a.db, db::Store::Role::kReadOnly);
  db::TestQuery q;
  if (!a.serial.empty()) q.serial = a.serial;
  if (!a.from.empty()) q.from = IsoOption("--from", a.from);
  if (!a.to.empty()) q.to = IsoOption("--to", a.to);
  if (!a.order.empty()) q.order_number = a.order;
  if (!a.outcome.empty()) q.outcome = analysis::ParseOutcome(a.outcome);
  q.limit = a.all ? a.page_size : a.limit;
  q.with_curves = a.format == "records";
  std::ofstream file;
  if (!a.out.empty()) {
    file.open(a.out, std::ios::binary);
    if (!file) throw std::runtime_error(a.out + ": cannot be written");
  }
  std::ostream& out = a.out.empty() ? std::cout : file;
  std::map<std::string, int> undeclared;  // measurement name -> tests that carry it
  std::int64_t done = 0;
  {
    Progress progress("export");
    if (a.format == "csv") out << db::ExportCsvHeader(columns);
    if (a.format != "csv") out << "[";
    // One page (all of it without --all); with --all the next page starts after the last
    // test written, so a store of any size is written page_size tests at a time.
    for (;;) {
      const std::vector<db::TestRecord> tests = store->Tests(q);
      const std::int64_t total = a.all ? -1 : static_cast<std::int64_t>(tests.size());
      for (const auto& t : tests) {
        if (a.format == "records") {
          out << (done == 0 ? "\n" : ",\n") << nlohmann::json(t).dump(1);
        } else {
          for (const std::string& n : db::ExportUndeclared(columns, t)) ++undeclared[n];
          if (a.format == "csv")
            out << db::ExportCsvRow(columns, t);
          else
            out << (done == 0 ? "\n" : ",\n") << db::ExportJsonRow(columns, t).dump();
        }
        progress.Update("tests", ++done, total);
      }
      if (!a.all || static_cast<int>(tests.size()) < q.limit) break;
      q.after = std::pair{tests.back().started_at, tests.back().id};
    }
    if (a.format != "csv") out << "\n]\n";
  }
  out.flush();
  if (!out) throw std::runtime_error("export: writing failed");
  std::cerr << "eol export: " << done << " test(s)";
  if (!a.all && done == a.limit)
    std::cerr << " (the --limit; narrow the range, raise --limit or give --all for more)";
  std::cerr << "\n";
  for (const auto& [name, n] : undeclared)
    std::cerr << "eol export: measurement " << name << " of " << n
              << " test(s) has no column (not declared: give its --recipe)\n";
  return 0;
}

}  // namespace

void AddExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Export finished tests for quality engineering, newest first, by serial, order, outcome\n"
      "and/or time range (ISO 8601 UTC, e.g. 2026-11-22T00:00:00.000Z; from inclusive, to\n"
      "exclusive). csv and json: one row per test in the export schema (deploy/OPERATIONS.md,\n"
      "\"Export schema\"; `--schema` prints it): fixed columns, the same for any data, with every\n"
      "declared measurement's value, sigma, limits, unit and outcome. records: full records\n"
      "with curves (what `eol teach --golden` reads).");
  cmd->add_option("--db", args->db, "SQLite file of the station")->check(CLI::ExistingFile);
  cmd->add_option("--serial", args->serial, "Only this serial");
  cmd->add_option("--from", args->from,
                  "Started at or after (ISO 8601: a date, or a time with Z or an offset)");
  cmd->add_option("--to", args->to,
                  "Started before (ISO 8601: a date, or a time with Z or an offset)");
  cmd->add_option("--order", args->order, "Only tests of this order/batch number");
  cmd->add_option("--outcome", args->outcome, "Only tests with this outcome")
      ->check(CLI::IsMember({"PASS", "FAIL", "ERROR", "ABORTED"}));
  cmd->add_option("--recipe", args->recipes,
                  "Recipe file(s) whose declared measurements (limits, masks, further phase\n"
                  "pairs) get columns after the standard ones; repeatable")
      ->check(CLI::ExistingFile);
  cmd->add_option("--format", args->format,
                  "csv or json (the export schema), or records (full records with curves)")
      ->capture_default_str()
      ->check(CLI::IsMember({"csv", "json", "records"}));
  cmd->add_flag("--json", args->json, "The same as --format json");
  cmd->add_option("--out", args->out, "Output file (default: stdout)");
  cmd->add_option("--limit", args->limit, "At most this many tests")
      ->capture_default_str()
      ->check(Between(1, 10000));
  cmd->add_flag("--all", args->all,
                "Every test that matches, read --page-size at a time (memory stays bounded)")
      ->excludes("--limit");
  cmd->add_option("--page-size", args->page_size, "With --all: tests read at a time")
      ->capture_default_str()
      ->check(Between(1, 10000));
  cmd->add_flag("--schema", args->schema,
                "Print the columns (Markdown table: column, type, unit, meaning) and exit");
  cmd->callback([args] { RunGuarded("export", [&] { return RunExport(*args); }); });
}

}  // namespace eol::station::cli
