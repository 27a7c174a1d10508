// `eol query --db FILE | --central URL --serial SN [--json] [--plot FILE [--test ID]
// [--recipe FILE]]`: the traceable history of one serial number, with who tested it and for
// which order; from one station's file, or plant-wide from the central PostgreSQL record
// (station/daemon/central/), with the same record fields. --plot
// draws the stored curve of its newest test (or --test ID) with the fitted model, the
// resonance window it was judged against and, given the recipe file of the record's hash,
// the masks (station/reports/curve_chart.h).
#include <cmath>
#include <complex>
#include <cstdio>
#include <iostream>

#include "db/serial_number.h"
#include "db/store.h"
#include "drivers/io/chart.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/central/central_record.h"
#include "station/daemon/central/pg.h"
#include "station/daemon/recipe.h"
#include "station/reports/curve_chart.h"

namespace eol::station::cli {
namespace {

// "380 .. 420", ">= 380", "<= 420" or "none": a measurement's limits as the text shows them.
std::string LimitText(const analysis::Limit& l) {
  char buf[64];
  if (l.lo && l.hi)
    std::snprintf(buf, sizeof buf, "%.6g .. %.6g", *l.lo, *l.hi);
  else if (l.lo)
    std::snprintf(buf, sizeof buf, ">= %.6g", *l.lo);
  else if (l.hi)
    std::snprintf(buf, sizeof buf, "<= %.6g", *l.hi);
  else
    return "none";
  return buf;
}

struct QueryArgs {
  std::string db;
  std::string central;
  std::string serial;
  bool json = false;
  bool curves = false;
  std::string plot;
  long long test_id = 0;
  std::string recipe;
};

const db::Curve* FindCurve(const db::TestRecord& t, const std::string& name) {
  for (const db::Curve& c : t.curves)
    if (c.name == name) return &c;
  return nullptr;
}

std::vector<std::complex<double>> Values(const db::Curve& c) {
  std::vector<std::complex<double>> v;
  for (std::size_t i = 0; i < c.re.size() && i < c.im.size(); ++i) v.emplace_back(c.re[i], c.im[i]);
  return v;
}

void WritePlot(const QueryArgs& a, const std::vector<db::TestRecord>& tests) {
  const db::TestRecord* t = &tests.front();
  if (a.test_id != 0) {
    t = nullptr;
    for (const db::TestRecord& r : tests)
      if (r.id == a.test_id) t = &r;
    if (!t)
      throw std::runtime_error("--test: " + a.serial + " has no test #" +
                               std::to_string(a.test_id));
  }
  const db::Curve* measured = FindCurve(*t, "impedance");
  if (!measured)
    throw std::runtime_error("--plot: test #" + std::to_string(t->id) +
                             " stored no impedance curve (outcome " +
                             analysis::ToString(t->outcome) + ")");
  CurvePlot p;
  p.title = "eol query " + a.serial + " test #" + std::to_string(t->id) + " " + t->started_at +
            " - recipe " + t->recipe_id + " v" + std::to_string(t->recipe_version) + ": " +
            analysis::ToString(t->outcome);
  p.freq_hz = measured->freq_hz;
  p.measured = Values(*measured);
  if (const db::Curve* model = FindCurve(*t, "model")) {
    p.model_freq_hz = model->freq_hz;
    p.model = Values(*model);
  }
  for (const analysis::Measurement& m : t->measurements)
    if (m.name == "resonance_f_hz") {
      p.resonance_window = m.limit;
      if (std::isfinite(m.value)) p.f0_hz = m.value;
    }
  for (const analysis::Reason& r : t->reasons) p.notes.push_back(r.text);
  if (!a.recipe.empty()) {
    const Recipe recipe = LoadRecipe(a.recipe);
    if (recipe.hash == t->recipe_hash)
      p.masks = recipe.masks;
    else
      p.notes.push_back("masks not drawn: " + a.recipe + " is not the recipe of this test");
  } else {
    p.notes.push_back("masks not drawn: give --recipe FILE of this test's recipe");
  }
  io::WriteChart(a.plot, CurveChart(p));
}

// " test 2 of 3" (the serial's attempt of the recipe's allowed tests), " test 2" without a
// limit, "" where the attempt is unknown (the central record keeps none).
std::string AttemptText(const db::TestRecord& t) {
  if (t.attempt <= 0) return "";
  return " test " + std::to_string(t.attempt) +
         (t.max_tests > 0 ? " of " + std::to_string(t.max_tests) : "");
}

int RunQuery(const QueryArgs& a) {
  std::string why;
  if (!db::ValidSerial(a.serial, &why)) throw std::runtime_error("--serial: " + why);
  if (a.db.empty() == a.central.empty())
    throw std::runtime_error("give --db FILE (one station) or --central URL (the plant), one");
  const bool curves = a.curves || !a.plot.empty();
  std::vector<db::TestRecord> tests;
  if (!a.central.empty()) {
    auto pg = central::PgConnection::Connect(a.central, 10, "query");
    tests = central::CentralTestsOfSerial(*pg, a.serial, curves);
  } else {
    tests = db::Store::Open(a.db, db::Store::Role::kReadOnly)->TestsOfSerial(a.serial, curves);
  }
  const std::string source = a.central.empty() ? a.db : central::RedactUrl(a.central);
  if (!a.plot.empty() && !tests.empty()) WritePlot(a, tests);
  if (a.json) {
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : tests) list.push_back(t);
    const nlohmann::json out = {
        {"serial", a.serial},
        {"latest", tests.empty() ? nlohmann::json() : nlohmann::json(tests.front())},
        {"tests", list}};
    std::cout << out.dump(2) << std::endl;
    return tests.empty() ? 1 : 0;
  }
  if (tests.empty()) {
    std::cout << a.serial << ": no tests in " << source << "\n";
    return 1;
  }
  std::cout << a.serial << ": " << tests.size() << " test(s), latest "
            << analysis::ToString(tests.front().outcome) << "\n";
  for (const auto& t : tests) {
    std::printf("  %s#%-6lld %s  %-7s recipe %s v%d (%s)%s%s\n",
                a.central.empty() ? "" : (t.station_id + " ").c_str(), static_cast<long long>(t.id),
                t.started_at.c_str(), analysis::ToString(t.outcome), t.recipe_id.c_str(),
                t.recipe_version, t.recipe_hash.substr(0, 12).c_str(), AttemptText(t).c_str(),
                t.retest_of ? (" retest of #" + std::to_string(*t.retest_of)).c_str() : "");
    if (t.work != db::WorkContext{})  // who and for which order (schema v4), when given
      std::printf("          operator %s, shift %s, order %s\n",
                  t.work.operator_id.empty() ? "-" : t.work.operator_id.c_str(),
                  t.work.shift.empty() ? "-" : t.work.shift.c_str(),
                  t.work.order_number.empty() ? "-" : t.work.order_number.c_str());
    for (const auto& m : t.measurements) {
      if (!std::isfinite(m.value)) continue;
      std::printf("          %-18s %12.6g %-4s limits %-21s [%s] %s\n", m.name.c_str(), m.value,
                  m.unit.c_str(), LimitText(m.limit).c_str(), analysis::ToString(m.outcome),
                  m.marginal ? "marginal" : "");
    }
    for (const auto& r : t.reasons)
      std::printf("          reason (%s): %s\n", analysis::ToString(r.code), r.text.c_str());
  }
  return 0;
}

}  // namespace

void AddQueryCommand(CLI::App& app) {
  auto args = std::make_shared<QueryArgs>();
  CLI::App* cmd = app.add_subcommand(
      "query",
      "Show every test of a serial number, newest first, with measurements, limits, outcome,\n"
      "reasons and recipe hash. Exit code 1 when the serial has no tests.");
  cmd->add_option("--db", args->db, "SQLite file of the station")->check(CLI::ExistingFile);
  cmd->add_option("--central", args->central,
                  "Plant-wide instead of --db: the central PostgreSQL record's URI\n"
                  "(postgresql://user@host:port/db), every station's tests");
  cmd->add_option("--serial", args->serial, "Serial number")->required();
  cmd->add_flag("--json", args->json, "One JSON object: {serial, latest, tests}");
  cmd->add_flag("--curves", args->curves, "With --json: include the raw curves");
  cmd->add_option("--plot", args->plot,
                  "Write the stored |Z| and Re Z of the newest test with the fitted model and\n"
                  "its limits (SVG, or PNG for .png)");
  cmd->add_option("--test", args->test_id, "With --plot: this test id instead of the newest");
  cmd->add_option("--recipe", args->recipe,
                  "With --plot: the recipe file of the test (its masks are drawn when its hash\n"
                  "is the test's)");
  cmd->callback([args] { RunGuarded("query", [&] { return RunQuery(*args); }); });
}

}  // namespace eol::station::cli
