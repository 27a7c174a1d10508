// `eol export --db FILE [--serial SN] [--from T] [--to T] [--format csv|json] [--out FILE]`:
// records out of the station for quality engineering (one CSV row per test with one column
// per measurement, or JSON records with curves).
#include <cmath>
#include <fstream>
#include <iostream>
#include <set>

#include "db/store.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"

namespace eol::station::cli {
namespace {

struct ExportArgs {
  std::string db;
  std::string serial;
  std::string from;
  std::string to;
  std::string format = "csv";
  std::string out;
  int limit = 10000;
};

// RFC 4180 quoting.
std::string Csv(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string Num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

void WriteCsv(std::ostream& out, const std::vector<db::TestRecord>& tests) {
  std::set<std::string> names;
  for (const auto& t : tests)
    for (const auto& m : t.measurements) names.insert(m.name);
  out << "id,serial,station_id,started_at,finished_at,outcome,recipe_id,recipe_version,"
         "recipe_hash,software_version,retest_of";
  for (const auto& n : names) out << "," << n;
  out << ",reasons\n";
  for (const auto& t : tests) {
    out << t.id << "," << Csv(t.serial) << "," << Csv(t.station_id) << "," << t.started_at << ","
        << t.finished_at << "," << analysis::ToString(t.outcome) << "," << Csv(t.recipe_id) << ","
        << t.recipe_version << "," << t.recipe_hash << "," << Csv(t.software_version) << ","
        << (t.retest_of ? std::to_string(*t.retest_of) : "");
    for (const auto& n : names) {
      std::string v;
      for (const auto& m : t.measurements)
        if (m.name == n) v = Num(m.value);
      out << "," << v;
    }
    std::string reasons;
    for (const auto& r : t.reasons) reasons += (reasons.empty() ? "" : "; ") + r.text;
    out << "," << Csv(reasons) << "\n";
  }
}

int RunExport(const ExportArgs& a) {
  auto store = db::Store::Open(a.db, db::Store::Role::kReader);
  db::TestQuery q;
  if (!a.serial.empty()) q.serial = a.serial;
  if (!a.from.empty()) q.from = a.from;
  if (!a.to.empty()) q.to = a.to;
  q.limit = a.limit;
  q.with_curves = a.format == "json";
  const std::vector<db::TestRecord> tests = store->Tests(q);
  std::ofstream file;
  if (!a.out.empty()) {
    file.open(a.out, std::ios::binary);
    if (!file) throw std::runtime_error(a.out + ": cannot be written");
  }
  std::ostream& out = a.out.empty() ? std::cout : file;
  if (a.format == "csv") {
    WriteCsv(out, tests);
  } else {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : tests) list.push_back(t);
    out << list.dump(1) << "\n";
  }
  out.flush();
  if (!out) throw std::runtime_error("export: writing failed");
  std::cerr << "eol export: " << tests.size() << " test(s)\n";
  return 0;
}

}  // namespace

void AddExportCommand(CLI::App& app) {
  auto args = std::make_shared<ExportArgs>();
  CLI::App* cmd = app.add_subcommand(
      "export",
      "Export finished tests as CSV (one row per test, one column per measurement) or JSON\n"
      "(full records with curves), by serial and/or time range (ISO 8601 UTC, e.g.\n"
      "2026-11-22T00:00:00.000Z; from inclusive, to exclusive).");
  cmd->add_option("--db", args->db, "SQLite file of the station")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--serial", args->serial, "Only this serial");
  cmd->add_option("--from", args->from, "Started at or after (ISO 8601 UTC)");
  cmd->add_option("--to", args->to, "Started before (ISO 8601 UTC)");
  cmd->add_option("--format", args->format, "csv or json")
      ->capture_default_str()
      ->check(CLI::IsMember({"csv", "json"}));
  cmd->add_option("--out", args->out, "Output file (default: stdout)");
  cmd->add_option("--limit", args->limit, "At most this many tests")
      ->capture_default_str()
      ->check(CLI::Range(1, 10000));
  cmd->callback([args] { RunGuarded("export", [&] { return RunExport(*args); }); });
}

}  // namespace eol::station::cli
