// Engineer charts end to end: `eol stats --plot`, `eol analyze --plot`, `eol query --plot`
// write SVG, and GET /api/charts/<measurement>.svg serves it. Each SVG is parsed by Python's
// XML parser (a document that does not parse fails the test); its root must be <svg>, the
// glyphs of its text must be drawn (cairo writes text as <use> of glyph outlines) and the
// words (its <title> and <desc>, the strings drawn) must hold the titles, labels and limit
// values computed by hand below.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <tuple>

#include "analysis/model/motor_model.h"
#include "db/store.h"
#include "drivers/io/frf_files.h"
#include "station/daemon/http_api.h"
#include "station/daemon/station.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using analysis::Outcome;
using eol::testing::ChildProcess;
using eol::testing::CliRun;

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

const std::string kRecipe = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";
const std::string kHash(64, 'c');

CliRun Eol(const std::vector<std::string>& args, bool merge_stderr = false) {
  return testing::RunEol(args, merge_stderr, 120s);
}

struct Svg {
  bool parsed = false;
  std::string root;
  std::string title;
  int glyphs = 0;      // <use> elements (drawn glyphs)
  std::string words;   // <title> and <desc>
  std::string report;  // what Python said, for failure messages
};

// Parses `path` with xml.dom.minidom.
Svg ParseSvg(const std::string& path) {
  const std::string script =
      "import sys, xml.dom.minidom as m\n"
      "d = m.parse(sys.argv[1]); r = d.documentElement\n"
      "text = lambda es: ''.join(n.data for e in es for n in e.childNodes if n.nodeType == 3)\n"
      "print('ROOT', r.tagName, r.getAttribute('xmlns'))\n"
      "print('GLYPHS', len(r.getElementsByTagName('use')))\n"
      "print('TITLE', text(r.getElementsByTagName('title')))\n"
      "print(text(r.getElementsByTagName('desc')))\n";
  ChildProcess p({"/usr/bin/python3", "-c", script, path}, true);
  const auto code = p.Wait(60s);
  Svg s;
  s.report = p.output();
  s.parsed = code && *code == 0;
  if (!s.parsed) return s;
  std::istringstream in(s.report);
  std::string line, tag;
  while (std::getline(in, line)) {
    if (line.rfind("ROOT ", 0) == 0) {
      s.root = line.substr(5);
    } else if (line.rfind("GLYPHS ", 0) == 0) {
      s.glyphs = std::stoi(line.substr(7));
    } else if (line.rfind("TITLE ", 0) == 0) {
      s.title = line.substr(6);
      s.words += s.title + "\n";
    } else {
      s.words += line + "\n";
    }
  }
  return s;
}

void ExpectSvg(const Svg& s) {
  ASSERT_TRUE(s.parsed) << s.report;
  EXPECT_EQ(s.root, "svg http://www.w3.org/2000/svg");
  EXPECT_GT(s.glyphs, 100) << "the text was not drawn";
}

db::TestRecord Unit(int i, Outcome o, double f0, double q) {
  char t[32], serial[16];
  std::snprintf(t, sizeof t, "2026-11-20T%02d:%02d:00.000Z", 8 + i / 60, i % 60);
  std::snprintf(serial, sizeof serial, "C-%03d", i + 1);
  db::TestRecord r;
  r.serial = serial;
  r.station_id = "s1";
  r.recipe_id = "pmsm-10pole";
  r.recipe_version = 1;
  r.recipe_hash = kHash;
  r.software_version = "test";
  r.started_at = t;
  r.finished_at = t;
  r.outcome = o;
  for (const auto& [name, unit, value, lo, hi] :
       {std::tuple{"resonance_f_hz", "Hz", f0, 370.0, 420.0},
        std::tuple{"resonance_q", "1", q, 20.0, 80.0}}) {
    analysis::Measurement m;
    m.name = name;
    m.unit = unit;
    m.value = value;
    m.limit.lo = lo;
    m.limit.hi = hi;
    m.outcome = analysis::MeasurementOutcome::kPass;
    r.measurements.push_back(m);
  }
  return r;
}

// 30 PASS units: f0 alternates 389, 391 for units 1-20, then 392, 394 for units 21-30 (a
// shift of +3 Hz); Q alternates 45, 47. Unit 31 FAILs at f0 = 425 Hz.
// I chart of f0 (PASS units): mean = (20 * 390 + 10 * 393) / 30 = 391; the moving ranges are
// 19 x 2, then |392 - 391| = 1, then 9 x 2: MRbar = 57 / 29 = 1.96552; UCL = 391 + 2.66 *
// 57 / 29 = 396.228, LCL = 385.772; MR UCL = 3.267 * 57 / 29 = 6.42134. Units 21-30 are all
// above 391 (units 1-20 touch it every other unit): rule 2 completes at unit 29 (C-029), its
// run starting at unit 21.
// Q: mean 46, MRbar 2, UCL 46 + 5.32 = 51.32, alternating: no alarm.
class ChartsTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto store = db::Store::Open(db_);
    for (int i = 0; i < 30; ++i) {
      const double f0 = (i < 20 ? 390.0 : 393.0) + (i % 2 == 0 ? -1.0 : 1.0);
      auto r = Unit(i, Outcome::kPass, f0, i % 2 == 0 ? 45.0 : 47.0);
      store->Insert(r);
    }
    auto fail = Unit(30, Outcome::kFail, 425.0, 46.0);
    store->Insert(fail);
  }
  eol::testing::TempDir dir_;
  std::string db_ = dir_ / "charts.sqlite";
};

TEST_F(ChartsTest, StatsPlotDrawsControlChartsAndHistogramsWithLimits) {
  const std::string svg = dir_ / "stats.svg";
  const CliRun r = Eol({"stats", "--db", db_, "--plot", svg});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_CONTAINS(r.out, "charts written to " + svg);
  EXPECT_CONTAINS(r.out, "RUN-RULE ALARM pmsm-10pole v1: resonance_f_hz rule 2");
  const Svg s = ParseSvg(svg);
  ExpectSvg(s);
  // Every measured unit by default, the FAIL unit marked, against the PASS units' limits
  // (4 significant digits).
  EXPECT_CONTAINS(s.title, "eol stats: recipe pmsm-10pole v1 (cccccccccccc), PASS and FAIL units");
  EXPECT_CONTAINS(s.words, "resonance_f_hz: individuals (I chart), 31 PASS and FAIL units");
  EXPECT_CONTAINS(s.words,
                  "control limits from the first 30 PASS units (all there are; 50 asked), "
                  "C-001..C-030");
  EXPECT_CONTAINS(s.words, "FAIL unit (1)");
  EXPECT_CONTAINS(s.words, "UCL 396.2\n");
  EXPECT_CONTAINS(s.words, "LCL 385.8\n");
  EXPECT_CONTAINS(s.words, "centre 391\n");
  EXPECT_CONTAINS(s.words, "UCL 6.421\n");  // MR chart
  EXPECT_CONTAINS(s.words, "LSL 370 Hz");
  EXPECT_CONTAINS(s.words, "USL 420 Hz");
  EXPECT_CONTAINS(s.words,
                  "resonance_f_hz rule 2: 9 points in a row above the centre line 391 at units "
                  "21-29 (serials C-021..C-029)");
  EXPECT_CONTAINS(s.words,
                  "resonance_f_hz rule 1: a point at 425 beyond the UCL 396.2 at unit 31 "
                  "(serial C-031)");
  EXPECT_CONTAINS(s.words, "resonance_f_hz: histogram of 31 PASS and FAIL units");
  EXPECT_CONTAINS(s.words, "FAIL units (1)");
  EXPECT_CONTAINS(s.words, "resonance_q: individuals (I chart), 31 PASS and FAIL units");
  EXPECT_CONTAINS(s.words, "UCL 51.32");
  EXPECT_CONTAINS(s.words, "Cp ");
  EXPECT_CONTAINS(s.words, "Pp ");
  EXPECT_CONTAINS(s.words, "unit (test order)");
  EXPECT_EQ(s.words.find("396.228"), std::string::npos) << "six digits where four say it";

  // PASS units only, on request: the FAIL unit is left out and the chart says so.
  const std::string pass = dir_ / "pass.svg";
  ASSERT_EQ(Eol({"stats", "--db", db_, "--population", "pass", "--plot", pass}).code, 0);
  const Svg a = ParseSvg(pass);
  ExpectSvg(a);
  EXPECT_CONTAINS(a.words, "resonance_f_hz: individuals (I chart), 30 PASS units");
  EXPECT_EQ(a.words.find("31 PASS and FAIL units"), std::string::npos);
  EXPECT_EQ(a.words.find("FAIL unit ("), std::string::npos);

  // PNG by extension.
  ASSERT_EQ(Eol({"stats", "--db", db_, "--plot", dir_ / "stats.png"}).code, 0);
  std::ifstream png(dir_ / "stats.png", std::ios::binary);
  std::string magic(8, '\0');
  png.read(magic.data(), 8);
  EXPECT_EQ(magic, "\x89PNG\r\n\x1a\n");
}

TEST_F(ChartsTest, StatsNamesCpAndPpAndCountsPassUnitsOnRequest) {
  const CliRun r = Eol({"stats", "--db", db_, "--population", "pass", "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["window"]["population"], "PASS units");
  const nlohmann::json& f0 = j["recipes"][0]["measurements"][0];
  ASSERT_EQ(f0["name"], "resonance_f_hz");
  EXPECT_EQ(f0["n"], 30);
  EXPECT_EQ(f0["fail"], 0);
  EXPECT_EQ(f0["caveat"], "");  // 30 units: enough for a capability index
  // sigma within = MRbar / 1.128 = (57 / 29) / 1.128 = 1.74248; Cp = 50 / (6 * 1.74248).
  EXPECT_NEAR(f0["sigma_within"].get<double>(), 57.0 / 29.0 / 1.128, 1e-9);
  EXPECT_NEAR(f0["cp"].get<double>(), 50.0 / (6.0 * 57.0 / 29.0 / 1.128), 1e-9);
  EXPECT_NEAR(f0["cpk"].get<double>(), (391.0 - 370.0) / (3.0 * 57.0 / 29.0 / 1.128), 1e-9);
  // Pp from the overall sd: sum of squares = 20 * 2^2 ... computed from the values.
  double ss = 0.0;
  for (int i = 0; i < 30; ++i) {
    const double v = (i < 20 ? 390.0 : 393.0) + (i % 2 == 0 ? -1.0 : 1.0);
    ss += (v - 391.0) * (v - 391.0);
  }
  const double s = std::sqrt(ss / 29.0);
  EXPECT_NEAR(f0["sd"].get<double>(), s, 1e-9);
  EXPECT_NEAR(f0["pp"].get<double>(), 50.0 / (6.0 * s), 1e-9);
  EXPECT_NEAR(f0["ppk"].get<double>(), 21.0 / (3.0 * s), 1e-9);
  EXPECT_EQ(f0["control"]["chart"], "imr");
  EXPECT_NEAR(f0["control"]["ucl"].get<double>(), 391.0 + 2.66 * 57.0 / 29.0, 1e-9);
  ASSERT_EQ(f0["control"]["alarms"].size(), 1u) << f0["control"].dump();
  EXPECT_EQ(f0["control"]["alarms"][0]["rule"], 2);
  EXPECT_EQ(f0["control"]["alarms"][0]["serial"], "C-029");
  ASSERT_EQ(j["spc_alarms"].size(), 1u) << j["spc_alarms"].dump();

  // By default every measured unit: the FAIL unit enters the figures and the chart, not its
  // limits (they come from the PASS units), so it raises rule 1.
  const CliRun all = Eol({"stats", "--db", db_, "--json"});
  ASSERT_EQ(all.code, 0) << all.out;
  const nlohmann::json ja = nlohmann::json::parse(all.out);
  EXPECT_EQ(ja["window"]["population"], "PASS and FAIL units");
  const nlohmann::json& fa = ja["recipes"][0]["measurements"][0];
  EXPECT_EQ(fa["n"], 31);
  EXPECT_EQ(fa["fail"], 1);
  EXPECT_EQ(fa["control"]["baseline_units"], 30);
  EXPECT_NEAR(fa["control"]["ucl"].get<double>(), 391.0 + 2.66 * 57.0 / 29.0, 1e-9);
  ASSERT_EQ(fa["control"]["alarms"].size(), 2u) << fa["control"].dump();
  EXPECT_EQ(fa["control"]["alarms"][1]["rule"], 1);
  EXPECT_EQ(fa["control"]["alarms"][1]["serial"], "C-031");

  const CliRun text = Eol({"stats", "--db", db_});
  EXPECT_CONTAINS(text.out,
                  "capability over PASS and FAIL units; Cp/Cpk from the within-subgroup sigma");
  EXPECT_CONTAINS(text.out, "Ppk");
  const CliRun bad = Eol({"stats", "--db", db_, "--population", "some"}, true);
  EXPECT_EQ(bad.code, 2);
  EXPECT_CONTAINS(bad.out, "--population must be all or pass");
  const CliRun base = Eol({"stats", "--db", db_, "--baseline", "1"}, true);
  EXPECT_EQ(base.code, 2);
  EXPECT_CONTAINS(base.out, "--baseline");
  const CliRun sub = Eol({"stats", "--db", db_, "--subgroup", "11"}, true);
  EXPECT_EQ(sub.code, 2);
  EXPECT_CONTAINS(sub.out, "subgroup must be 1 (I-MR) or 2..10 (X-bar/R)");
}

// Eight units below the lower spec after 30 good ones: charted against the limits of the PASS
// units, every one of them alarms (rule 1), and the overall capability (Ppk) of all 38 units
// says what the process did. A PASS-only chart shows none of them.
TEST(HonestSpc, EightUnitsBelowTheLowerSpecAlarmAgainstTheBaselineLimits) {
  eol::testing::TempDir dir;
  const std::string db = dir / "drop.sqlite";
  {
    auto store = db::Store::Open(db);
    for (int i = 0; i < 38; ++i) {
      const bool bad = i >= 30;
      const double f0 = bad ? 365.0 + (i % 2) : 390.0 + (i % 2 == 0 ? -1.0 : 1.0);
      auto unit = Unit(i, bad ? Outcome::kFail : Outcome::kPass, f0, 46.0 + (i % 2));
      store->Insert(unit);
    }
  }
  const CliRun r = Eol({"stats", "--db", db, "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json f0 = nlohmann::json::parse(r.out)["recipes"][0]["measurements"][0];
  EXPECT_EQ(f0["n"], 38);
  EXPECT_EQ(f0["fail"], 8);
  EXPECT_EQ(f0["control"]["baseline_units"], 30);
  EXPECT_NEAR(f0["control"]["lcl"].get<double>(), 390.0 - 2.66 * 2.0, 1e-9);
  int beyond = 0;
  for (const auto& a : f0["control"]["alarms"]) beyond += a["rule"] == 1 ? 1 : 0;
  EXPECT_EQ(beyond, 8) << f0["control"].dump();
  EXPECT_LT(f0["ppk"].get<double>(), 1.0) << "the eight spread the units over the LSL";

  const CliRun pass = Eol({"stats", "--db", db, "--population", "pass", "--json"});
  ASSERT_EQ(pass.code, 0) << pass.out;
  const nlohmann::json p0 = nlohmann::json::parse(pass.out)["recipes"][0]["measurements"][0];
  EXPECT_EQ(p0["n"], 30);
  EXPECT_TRUE(p0["control"]["alarms"].empty()) << p0["control"].dump();
}

TEST_F(ChartsTest, ApiServesChartsAndRefusesBadRequestsWithJson) {
  station::StatusBoard board("api");
  station::HttpOptions o;
  o.port = 0;
  o.db_path = db_;
  station::HttpApi api(board, o, {});
  api.Start();
  httplib::Client http("127.0.0.1", api.port());
  auto get_svg = [&](const std::string& query) {
    auto res = http.Get(query);
    EXPECT_TRUE(res) << query;
    if (!res) return Svg{};
    EXPECT_EQ(res->status, 200) << query << ": " << res->body;
    EXPECT_EQ(res->get_header_value("Content-Type"), "image/svg+xml") << query;
    const std::string path = dir_ / "api.svg";
    std::ofstream(path, std::ios::binary) << res->body;
    return ParseSvg(path);
  };
  const Svg imr = get_svg("/api/charts/resonance_f_hz.svg");
  ExpectSvg(imr);
  EXPECT_CONTAINS(imr.title,
                  "resonance_f_hz individuals / moving range (I-MR) - recipe pmsm-10pole");
  EXPECT_CONTAINS(imr.words, "UCL 396.2\n");
  EXPECT_CONTAINS(imr.words, "(serials C-021..C-029)");

  // The newest 10 PASS units: units 21-30 alternate 392, 394: mean 393, MRbar 2, UCL 398.32;
  // 10 baseline units are said to be too few for settled limits.
  const Svg last = get_svg("/api/charts/resonance_f_hz.svg?last=10&chart=imr&population=pass");
  ExpectSvg(last);
  EXPECT_CONTAINS(last.words, "individuals (I chart), 10 PASS units");
  EXPECT_CONTAINS(last.words, "UCL 398.3\n");
  EXPECT_CONTAINS(last.words,
                  "control limits from only 10 baseline units (20 or more for settled limits)");

  // A baseline of the first 20 PASS units: units 1-20 alternate 389, 391: centre 390, MRbar 2,
  // UCL 395.32; every later unit is charted against those limits.
  const Svg base = get_svg("/api/charts/resonance_f_hz.svg?baseline=20");
  ExpectSvg(base);
  EXPECT_CONTAINS(base.words, "control limits from the first 20 PASS units, C-001..C-020");
  EXPECT_CONTAINS(base.words, "UCL 395.3\n");
  EXPECT_CONTAINS(base.words, "centre 390\n");

  // X-bar/R of Q with subgroups of 5 consecutive units: 30 units make 6 subgroups.
  const Svg xr = get_svg("/api/charts/resonance_q.svg?chart=xbar_r&subgroup=5");
  ExpectSvg(xr);
  EXPECT_CONTAINS(xr.words, "resonance_q: subgroup means (X-bar chart), 6 subgroups of 5");
  EXPECT_CONTAINS(xr.words, "subgroup ranges (R chart)");
  EXPECT_CONTAINS(xr.words, "the last 1 units make no whole subgroup");
  EXPECT_EQ(xr.words.find("USL"), std::string::npos) << "spec limits bound units, not means";
  EXPECT_EQ(xr.words.find("LSL"), std::string::npos) << "spec limits bound units, not means";

  const Svg h = get_svg("/api/charts/resonance_f_hz.svg?chart=histogram&population=all");
  ExpectSvg(h);
  EXPECT_CONTAINS(h.words, "resonance_f_hz: histogram of 31 PASS and FAIL units");
  EXPECT_CONTAINS(h.words, "LSL 370 Hz");
  EXPECT_CONTAINS(h.words, "USL 420 Hz");
  EXPECT_CONTAINS(h.words, "Cpk ");
  EXPECT_CONTAINS(h.words, "Ppk ");

  for (const auto& [query, status, code] : std::vector<std::tuple<std::string, int, std::string>>{
           {"/api/charts/nope.svg", 404, "unknown_measurement"},
           {"/api/charts/resonance_f_hz.svg?chart=pie", 400, "bad_chart"},
           {"/api/charts/resonance_f_hz.svg?subgroup=11", 400, "bad_subgroup"},
           {"/api/charts/resonance_f_hz.svg?last=0", 400, "bad_last"},
           {"/api/charts/resonance_f_hz.svg?last=5x", 400, "bad_last"},
           {"/api/charts/resonance_f_hz.svg?subgrup=3", 400, "unknown_parameter"},
           {"/api/charts/resonance_f_hz.svg?population=good", 400, "bad_population"},
           {"/api/charts/resonance_f_hz.svg?baseline=1", 400, "bad_baseline"},
           {"/api/charts/resonance_f_hz.svg?from=2027-01-01T00:00:00Z", 404, "no_units"},
           {"/api/charts/winding_r_ohm.svg", 404, "no_units"}}) {
    auto res = http.Get(query);
    ASSERT_TRUE(res) << query;
    EXPECT_EQ(res->status, status) << query << ": " << res->body;
    const nlohmann::json j = nlohmann::json::parse(res->body, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << query << ": " << res->body;
    EXPECT_EQ(j["error"]["code"], code) << query << ": " << res->body;
  }
  api.Stop();
}

analysis::Frf NoisyZ(double f0_hz, double sigma, std::uint64_t seed) {
  std::vector<double> f;
  for (int k = 200; k <= 800; ++k) f.push_back(k);
  analysis::Frf z = analysis::MotionalImpedance{0.5, 2.0e-3, 0.51, f0_hz, 50.0}.Evaluate(f);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma / std::sqrt(2.0));
  for (auto& v : z.value) v += std::complex<double>(n(rng), n(rng));
  z.sigma.assign(f.size(), sigma);
  return z;
}

TEST(CurvePlots, AnalyzePlotDrawsCurveModelWindowAndMask) {
  eol::testing::TempDir dir;
  io::WriteFrfCsv(dir / "z.csv", NoisyZ(390.0, 0.02, 3));
  const std::string svg = dir / "analyze.svg";
  const CliRun r =
      Eol({"analyze", "--measured", dir / "z.csv", "--recipe", kRecipe, "--plot", svg});
  ASSERT_EQ(r.code, 0) << r.out;
  const Svg s = ParseSvg(svg);
  ExpectSvg(s);
  EXPECT_CONTAINS(s.title, "eol analyze " + (dir / "z.csv") + " - recipe pmsm-10pole v");
  EXPECT_CONTAINS(s.title, ": PASS");
  EXPECT_CONTAINS(s.words, "measured |Z|");
  EXPECT_CONTAINS(s.words, "fitted model |Z|");
  EXPECT_CONTAINS(s.words, "measured Re Z");
  EXPECT_CONTAINS(s.words, "fitted model Re Z");
  EXPECT_CONTAINS(s.words, "resonance window [");
  EXPECT_CONTAINS(s.words, "mask re_z_low_band hi");           // the recipe's Re Z mask
  EXPECT_CONTAINS(s.words, "resonance window [370, 420] Hz");  // the recipe's limits
  EXPECT_CONTAINS(s.words, "fitted f0 ");
  EXPECT_CONTAINS(s.words, "frequency (Hz)");

  // Without a recipe there are no limits, and the chart says so.
  const std::string bare = dir / "bare.svg";
  ASSERT_EQ(Eol({"analyze", "--measured", dir / "z.csv", "--plot", bare}).code, 0);
  const Svg b = ParseSvg(bare);
  ExpectSvg(b);
  EXPECT_CONTAINS(b.words, "no --recipe: no limits or masks drawn");
  EXPECT_EQ(b.words.find("resonance window"), std::string::npos);

  // A plot that cannot be written is a file error (exit 2).
  const CliRun no =
      Eol({"analyze", "--measured", dir / "z.csv", "--plot", dir / "no/such.svg"}, true);
  EXPECT_EQ(no.code, 2) << no.out;
}

TEST(CurvePlots, QueryPlotDrawsTheStoredCurveOfATest) {
  eol::testing::TempDir dir;
  const nlohmann::json j = {
      {"station_id", "plot"},       {"recipe", kRecipe},
      {"db", dir / "q.sqlite"},     {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}, {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}}};
  {
    station::Station st(station::ParseStationConfig(j, "test", ""));
    const db::TestRecord r = st.RunTest("Q-1");
    ASSERT_NE(r.outcome, Outcome::kError);
  }
  const std::string svg = dir / "query.svg";
  const CliRun r = Eol(
      {"query", "--db", dir / "q.sqlite", "--serial", "Q-1", "--plot", svg, "--recipe", kRecipe});
  ASSERT_EQ(r.code, 0) << r.out;
  const Svg s = ParseSvg(svg);
  ExpectSvg(s);
  EXPECT_CONTAINS(s.title, "eol query Q-1 test #1");
  EXPECT_CONTAINS(s.words, "measured |Z|");
  EXPECT_CONTAINS(s.words, "fitted model Re Z");
  EXPECT_CONTAINS(s.words, "resonance window [");
  EXPECT_CONTAINS(s.words, "mask re_z_low_band hi");

  // Without the recipe the masks are not drawn and the chart says why.
  const std::string bare = dir / "bare.svg";
  ASSERT_EQ(Eol({"query", "--db", dir / "q.sqlite", "--serial", "Q-1", "--plot", bare}).code, 0);
  const Svg b = ParseSvg(bare);
  ExpectSvg(b);
  EXPECT_CONTAINS(b.words, "masks not drawn: give --recipe FILE");
  EXPECT_EQ(b.words.find("mask re_z_low_band"), std::string::npos);
  const CliRun none = Eol(
      {"query", "--db", dir / "q.sqlite", "--serial", "Q-1", "--plot", bare, "--test", "99"}, true);
  EXPECT_EQ(none.code, 2);
  EXPECT_CONTAINS(none.out, "--test: Q-1 has no test #99");
}

}  // namespace
}  // namespace eol
