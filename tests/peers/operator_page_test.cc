// The operator page in a real browser (Debian's chromium, driven by playwright-core from
// npm): the daemon runs on its simulators, a test is run, and the page must show the stored
// verdict, the serial and the measured curve against the recipe's mask, then follow a second
// test live; and a scanner typing serials into the page starts tests whose verdicts must fit
// and be readable at two screen sizes, with axe-core in the page. Screenshots are kept in
// build/artifacts/ for CI.
#include <gtest/gtest.h>

#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <thread>

#include "../support/child_process.h"
#include "../support/gap_units.h"
#include "../support/station_ready.h"
#include "../support/stored_test.h"
#include "analysis/qc/measurement.h"
#include "db/store.h"
#include "drivers/io/frf_files.h"
#include "station/daemon/reason_cause.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

const std::string kBrowserDir = std::string(EOL_SOURCE_DIR) + "/tests/peers/browser";

using eol::testing::PortFromReadyLine;
using eol::testing::RunStoredTest;

std::string NodeBinary() {
  for (const char* p : {"/usr/local/bin/node", "/usr/bin/node", "/usr/bin/nodejs"})
    if (std::filesystem::exists(p)) return p;
  return "";
}

// node.js, once Debian's chromium, node and the npm modules the browser checks use are there;
// otherwise "" and the test has failed saying which is missing.
std::string BrowserCheckNode() {
  const std::string node = NodeBinary();
  if (!std::filesystem::exists("/usr/bin/chromium"))
    ADD_FAILURE() << "Debian's chromium is a declared test dependency "
                     "(deploy/install-deps.sh --tests)";
  else if (node.empty())
    ADD_FAILURE() << "node.js is a declared test dependency";
  else if (!std::filesystem::exists(kBrowserDir + "/node_modules/axe-core/axe.min.js") ||
           !std::filesystem::exists(kBrowserDir + "/node_modules/playwright-core"))
    ADD_FAILURE() << "run `npm ci` in tests/peers/browser (deploy/run-tests.sh does)";
  else
    return node;
  return "";
}

// One point per excited line of the shipped recipe's multisine (f_lo..f_hi at line_spacing).
nlohmann::json ShippedRecipe() {
  return nlohmann::json::parse(
      std::ifstream(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"));
}

// One table row per judged measurement: each limit and each mask's lines-outside count.
int ShippedRecipeMeasurements() {
  const nlohmann::json recipe = ShippedRecipe();
  return static_cast<int>(recipe["limits"].size() + recipe["masks"].size());
}

int ShippedRecipeLines() {
  const nlohmann::json recipe = ShippedRecipe();
  const auto& e = recipe["excitation"];
  return static_cast<int>(std::lround((e["f_hi_hz"].get<double>() - e["f_lo_hz"].get<double>()) /
                                      e["line_spacing_hz"].get<double>())) +
         1;
}

// `eol station --config DIR/station.json --web-root station/web` with `config`, started and
// listening (its port in *port).
std::unique_ptr<ChildProcess> StartPageStation(const eol::testing::TempDir& dir,
                                               const nlohmann::json& config, int* port) {
  std::ofstream(dir / "station.json") << config.dump();
  auto station = std::make_unique<ChildProcess>(
      std::vector<std::string>{EOL_BINARY, "station", "--config", dir / "station.json",
                               "--web-root", std::string(EOL_SOURCE_DIR) + "/station/web"});
  EXPECT_TRUE(station->WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station->output();
  *port = PortFromReadyLine(station->output());
  return station;
}

TEST(OperatorPage, ShowsVerdictCurveAndFollowsTestsLive) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());

  eol::testing::TempDir dir;
  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "page-test"},
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", dir / "s.sqlite"},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}}.dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json", "--web-root",
                        std::string(EOL_SOURCE_DIR) + "/station/web"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  const int port = PortFromReadyLine(station.output());
  httplib::Client http("127.0.0.1", port);
  auto res = http.Post("/api/tests", R"({"serial": "PAGE-0001"})", "application/json");
  ASSERT_TRUE(res && res->status == 202);
  std::string outcome;
  for (int i = 0; i < 300 && outcome.empty(); ++i) {
    res = http.Get("/api/units/PAGE-0001");
    if (res && res->status == 200) {
      const auto tests = nlohmann::json::parse(res->body)["tests"];
      if (!tests.empty()) outcome = tests[0]["outcome"];
    }
    std::this_thread::sleep_for(100ms);
  }
  ASSERT_FALSE(outcome.empty()) << "the first test was not stored";

  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  const std::string shot = artifacts + "/operator-page.png";
  std::filesystem::remove(shot);
  ChildProcess browser({node, kBrowserDir + "/check_page.mjs",
                        "http://127.0.0.1:" + std::to_string(port), shot, "PAGE-0001", "PAGE-0002"},
                       /*merge_stderr=*/false);
  const auto code = browser.Wait(180s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output();
  const auto j = nlohmann::json::parse(browser.output());
  EXPECT_EQ(j["first"]["verdict"], outcome);
  EXPECT_EQ(j["first"]["serial"], "PAGE-0001");
  EXPECT_EQ(j["first"]["points"], ShippedRecipeLines()) << "the measured curve is not drawn";
  EXPECT_EQ(j["first"]["model"], 1);
  EXPECT_GE(j["first"]["masks"].get<int>(), 1) << "the recipe's mask is not drawn";
  EXPECT_EQ(j["first"]["measurements"], ShippedRecipeMeasurements());
  // The station runs on its simulators: the page says so, unmissably (issue 14).
  EXPECT_NE(j["first"]["simulation"].get<std::string>().find("SIMULATION"), std::string::npos)
      << j["first"];
  EXPECT_EQ(j["second"]["serial"], "PAGE-0002");
  EXPECT_EQ(j["second"]["connection"], "live");
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  EXPECT_TRUE(std::filesystem::file_size(shot) > 10000) << "no screenshot";
  station.Stop(SIGTERM, 20s);
}

// Issue 17: a recipe that measures two phase pairs and bounds |Z| as well as Re Z. The page
// draws what the record stored, every pair (not only the first), and the |Z| mask in its own
// panel under the Re Z one; the legend names the pairs and both kinds of mask.
TEST(OperatorPage, DrawsEveryPhasePairAndTheAbsZMasks) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());

  eol::testing::TempDir dir;
  nlohmann::json recipe = ShippedRecipe();
  recipe["excitation"].erase("phase_pair");
  recipe["excitation"]["phase_pairs"] = {0, 1};
  // |Z| of the shipped motor is about 2 pi f L = 6.3 ohm at 500 Hz and 10 ohm at 800 Hz.
  recipe["masks"].push_back(
      {{"name", "abs_z_band"},
       {"quantity", "abs_ohm"},
       {"max_lines_outside", 0},
       {"points",
        {{{"f_hz", 500}, {"lo", 4.0}, {"hi", 14.0}}, {{"f_hz", 800}, {"lo", 4.0}, {"hi", 14.0}}}}});
  std::ofstream(dir / "pairs.json") << recipe.dump();
  int port = 0;
  const auto station = StartPageStation(dir,
                                        {{"station_id", "page-pairs"},
                                         {"recipe", dir / "pairs.json"},
                                         {"db", dir / "s.sqlite"},
                                         {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
                                         {"fixture", {{"driver", "sim"}}},
                                         {"daq", {{"driver", "sim"}}},
                                         {"sim", {{"population", {{"defect_share", 0.0}}}}}},
                                        &port);
  ASSERT_GT(port, 0);
  httplib::Client http("127.0.0.1", port);
  const nlohmann::json stored = RunStoredTest(http, "PAIRS-0001");
  ASSERT_FALSE(stored.is_null()) << "the test was not stored";
  ASSERT_EQ(stored["outcome"], "PASS") << stored["reasons"];
  const auto res = http.Get("/api/tests/" + std::to_string(stored["id"].get<long long>()));
  ASSERT_TRUE(res && res->status == 200);
  const nlohmann::json record = nlohmann::json::parse(res->body);
  std::set<std::string> curves;
  for (const auto& c : record["curves"]) curves.insert(c["name"]);
  ASSERT_EQ(curves, (std::set<std::string>{"impedance", "model", "impedance@V-W", "model@V-W"}));

  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  ChildProcess browser({node, kBrowserDir + "/check_curves.mjs",
                        "http://127.0.0.1:" + std::to_string(port), artifacts, "PAIRS-0001"},
                       /*merge_stderr=*/false);
  const auto code = browser.Wait(120s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output();
  const auto j = nlohmann::json::parse(browser.output());
  const int lines = ShippedRecipeLines();
  const nlohmann::json both = {{{"pair", "U-V"}, {"points", lines}},
                               {{"pair", "V-W"}, {"points", lines}}};
  for (const char* panel : {"re", "abs"}) {
    const nlohmann::json& p = j[panel];
    EXPECT_FALSE(p["hidden"].get<bool>()) << panel;
    EXPECT_EQ(p["serial"], "PAIRS-0001") << panel;
    EXPECT_EQ(p["measured"], both) << panel << ": every pair's measured curve";
    EXPECT_EQ(p["model"], both) << panel << ": every pair's fitted model";
    EXPECT_EQ(p["last"], "model") << panel << ": the models on top";
    EXPECT_EQ(p["f0_lines"], 2) << panel;
    EXPECT_DOUBLE_EQ(p["window"]["lo"].get<double>(), 370.0) << panel;
    EXPECT_DOUBLE_EQ(p["window"]["hi"].get<double>(), 420.0) << panel;
  }
  // Re Z: the shipped recipe's ceiling (hi only); |Z|: the band's two bounds.
  EXPECT_EQ(j["re"]["masks"], (nlohmann::json{{{"mask", "re_z_low_band"}, {"bound", "hi"}}}));
  EXPECT_EQ(j["abs"]["masks"], (nlohmann::json{{{"mask", "abs_z_band"}, {"bound", "lo"}},
                                               {{"mask", "abs_z_band"}, {"bound", "hi"}}}));
  EXPECT_NE(j["abs"]["label"].get<std::string>().find("|Z| of PAIRS-0001"), std::string::npos);
  std::vector<std::string> legend;
  for (const auto& k : j["legend"]) legend.push_back(k[1]);
  for (const char* want : {"measured U-V", "measured V-W", "fitted model U-V", "fitted model V-W",
                           "limit mask: Re Z must stay out of the shaded area",
                           "limit mask: |Z| must stay out of the shaded area"})
    EXPECT_NE(std::find(legend.begin(), legend.end(), want), legend.end())
        << want << " not in the legend: " << j["legend"];
  std::set<std::string> rows(j["measurements"].begin(), j["measurements"].end());
  EXPECT_TRUE(rows.count("resonance_f_hz@V-W") && rows.count("mask_abs_z_band_lines_outside"))
      << j["measurements"];
  for (const char* size : {"1280x800", "1920x1080"}) {
    EXPECT_TRUE(j["sizes"][size]["axe"].empty()) << size << ": " << j["sizes"][size]["axe"];
    EXPECT_GT(j["sizes"][size]["abs_height_px"].get<double>(), 100.0) << size;
  }
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  for (const auto& shot : j["screenshots"])
    EXPECT_GT(std::filesystem::file_size(shot.get<std::string>()), 10000u) << shot;
  station->Stop(SIGTERM, 20s);
}

// The recipe's instructions (issue 17): the page shows the one the plant wrote for the
// outcome under the catalogue's instruction for the reason (issue 36).
nlohmann::json ShippedInstructions() {
  std::ifstream in(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  return nlohmann::json::parse(in).at("instructions");
}

// The operator page's words in `language` (station/web/i18n/).
nlohmann::json Catalogue(const std::string& language) {
  std::ifstream in(std::string(EOL_SOURCE_DIR) + "/station/web/i18n/" + language + ".json");
  return nlohmann::json::parse(in);
}

// The scanned serials' stored records, as the page showed them; returns SCAN-GOOD-1's.
nlohmann::json ExpectStoredAsShown(int port, const nlohmann::json& j) {
  const nlohmann::json& states = j["states"];
  // What the page shows is what the station stored for the scanned serials, and the page's
  // start carried the operator and shift typed into it.
  httplib::Client http("127.0.0.1", port);
  auto stored = [&](const std::string& serial) {
    const auto res = http.Get("/api/units/" + serial);
    EXPECT_TRUE(res && res->status == 200);
    const auto tests = nlohmann::json::parse(res->body)["tests"];
    return tests.empty() ? nlohmann::json() : tests[0];
  };
  const nlohmann::json good = stored("SCAN-GOOD-1");
  EXPECT_FALSE(good.is_null()) << "the scanned serial was not tested";
  EXPECT_EQ(good["outcome"], "PASS");
  EXPECT_EQ(states["pass"]["verdict"], "PASS");
  EXPECT_EQ(good["operator_id"], "op-17");
  EXPECT_EQ(good["shift"], "B");
  EXPECT_NE(states["pass"]["tested"].get<std::string>().find("operator op-17 · shift B"),
            std::string::npos)
      << states["pass"]["tested"];
  EXPECT_EQ(stored("SCAN-BAD-1")["outcome"], "FAIL");
  EXPECT_EQ(states["fail"]["verdict"], "FAIL");
  // Retest marking: nothing on a first test; the serial's second test reads "retest 2 of 3",
  // as its stored record says.
  EXPECT_EQ(states["fail"]["attempt"], "");
  EXPECT_EQ(j["retest"]["attempt"], "retest 2 of 3");
  EXPECT_EQ(j["retest"]["verdict"], "FAIL");
  EXPECT_EQ(stored("SCAN-BAD-1")["attempt"], 2);
  EXPECT_EQ(stored("SCAN-BAD-1")["max_tests"], 3);
  EXPECT_TRUE(stored("SCAN-LOCKED-1").is_null()) << "a refused serial is not stored";
  return good;
}

void ExpectLockoutAndInstructions(const nlohmann::json& j) {
  const nlohmann::json& states = j["states"];
  const nlohmann::json instructions = ShippedInstructions();
  // Lockout: a banner; the refused serial is ERROR with the catalogue's instruction for a
  // lockout above the reason (the recipe's "error" instruction is its default: not shown);
  // ERROR's lamp is not FAIL's. FAIL: the catalogue's instruction, then the recipe's own.
  const nlohmann::json en = Catalogue("en");
  EXPECT_NE(states["lockout"]["lockout"].get<std::string>().find("LOCKED OUT"), std::string::npos);
  EXPECT_EQ(states["error"]["sizes"]["1280x800"]["verdict"]["text"], "ERROR");
  EXPECT_EQ(states["error"]["instruction"], en["do.lockout"]);
  ASSERT_FALSE(states["error"]["reasons"].empty());
  EXPECT_NE(states["error"]["reasons"][0].get<std::string>().find("locked out"), std::string::npos);
  const std::string fail_instruction = states["fail"]["instruction"];
  EXPECT_EQ(fail_instruction.rfind(en["do.limit"].get<std::string>(), 0), 0u) << fail_instruction;
  EXPECT_NE(fail_instruction.find(instructions["fail"].get<std::string>()), std::string::npos)
      << fail_instruction;
  EXPECT_EQ(states["pass"]["instruction"], "");
  for (const char* size : {"words_1280x800", "words_1920x1080"}) {
    const nlohmann::json& w = j[size];
    EXPECT_NE(w["ERROR"]["background"], w["FAIL"]["background"]) << size;
    EXPECT_NE(w["ABORTED"]["background"], w["FAIL"]["background"]) << size;
    // Every word the lamp can show fits its box (scrollWidth <= clientWidth).
    for (const char* word : {"PASS", "FAIL", "ERROR", "ABORTED", "TESTING"})
      EXPECT_TRUE(w[word]["fits"].get<bool>()) << size << " " << word << ": " << w[word];
  }
}

void ExpectEveryStateFitsAtBothSizes(const nlohmann::json& states) {
  // Each state at both sizes: the verdict fits and is large; axe finds nothing serious.
  for (const char* state : {"lockout", "error", "testing", "pass", "fail"}) {
    for (const char* size : {"1280x800", "1920x1080"}) {
      const nlohmann::json& s = states[state]["sizes"][size];
      EXPECT_TRUE(s["verdict"]["fits"].get<bool>()) << state << " " << size << ": " << s["verdict"];
      // Readable at 3 m: a font of at least 64 px at 1280 and 96 px at 1920.
      EXPECT_GE(s["verdict"]["font_px"].get<double>(), size == std::string("1280x800") ? 64 : 96)
          << state << " " << size;
      if (s.contains("axe")) {
        EXPECT_TRUE(s["axe"].empty()) << state << " " << size << ": " << s["axe"];
      }
    }
  }
  EXPECT_EQ(states["testing"]["sizes"]["1280x800"]["verdict"]["text"], "TESTING");
  EXPECT_EQ(states["testing"]["sizes"]["1920x1080"]["verdict"]["text"], "TESTING");
  EXPECT_EQ(states["lockout"]["focus"], "scan");
}

void ExpectChartAndMeasurements(const nlohmann::json& states, const nlohmann::json& good) {
  // The chart: the resonance window from the limit the verdict used, the mask, the measured
  // curve, and the fitted model drawn last (on top); each in the legend.
  const nlohmann::json& chart = states["pass"]["chart"];
  EXPECT_DOUBLE_EQ(chart["window"]["lo"].get<double>(), 370.0) << chart;
  EXPECT_DOUBLE_EQ(chart["window"]["hi"].get<double>(), 420.0) << chart;
  EXPECT_GE(chart["masks"].get<int>(), 1);
  EXPECT_EQ(chart["measured_points"], ShippedRecipeLines());
  EXPECT_EQ(chart["model_points"], ShippedRecipeLines());
  EXPECT_EQ(chart["order"].back(), "model") << chart["order"];
  std::vector<std::string> legend;
  for (const auto& k : chart["legend"]) legend.push_back(k[0]);
  EXPECT_EQ(legend, (std::vector<std::string>{"measured", "model", "window", "mask", "f0"}));

  // Measurements in the operator's words and units, with the stored values.
  std::map<std::string, nlohmann::json> shown;
  for (const auto& m : states["pass"]["measurements"]) shown[m["name"]] = m;
  ASSERT_EQ(shown.size(), good["measurements"].size());
  EXPECT_EQ(shown["resonance_f_hz"]["label"], "Resonance");
  EXPECT_EQ(shown["resonance_q"]["label"], "Quality factor Q");
  EXPECT_EQ(shown["winding_l_h"]["label"], "Winding inductance");
  EXPECT_EQ(shown["resonance_f_hz"]["limits"], "370 … 420 Hz");
  EXPECT_EQ(shown["winding_l_h"]["limits"], "1.6 … 2.4 mH");
  EXPECT_EQ(shown["fit_chi2_per_dof"]["limits"], "≤ 3");
  for (const auto& m : good["measurements"]) {
    if (m["name"] != "resonance_f_hz") continue;
    const double f0 = m["value"].get<double>();
    std::ostringstream want;
    want << std::showpoint << std::setprecision(4) << f0 << " Hz";  // as "390.1 Hz"
    EXPECT_EQ(shown["resonance_f_hz"]["value"], want.str());
  }
}

void ExpectLocalTimeWithZone(const nlohmann::json& states) {
  // Local time with its zone: the browser runs in Asia/Kolkata (UTC+5:30, no summer time).
  ASSERT_FALSE(states["pass"]["history"].empty());
  const nlohmann::json& row = states["pass"]["history"][0];
  EXPECT_EQ(row["serial"], "SCAN-GOOD-1");
  std::tm utc{};
  std::istringstream(row["utc"].get<std::string>()) >> std::get_time(&utc, "%Y-%m-%dT%H:%M:%S");
  const int local_min = (utc.tm_hour * 60 + utc.tm_min + 330) % (24 * 60);
  char hhmm[8];
  std::snprintf(hhmm, sizeof hhmm, "%02d:%02d", local_min / 60, local_min % 60);
  const std::string shown_time = row["shown"];
  EXPECT_EQ(shown_time.rfind(hhmm, 0), 0u) << shown_time << " for " << row["utc"];
  EXPECT_NE(shown_time.find("GMT+5:30"), std::string::npos) << shown_time;
}

// Issue 17: a keyboard-wedge scanner starts tests from the page; the verdict fits its box
// and stays large at 1280x800 and 1920x1080; ERROR is not dressed as FAIL; the recipe's
// instruction stands above the reason; the chart draws the model on top and every limit the
// verdict used; the lockout and the simulation are banners; times are local with their zone;
// axe-core finds nothing serious. Screenshots of each state at both sizes are kept.
TEST(OperatorPage, ScannerStartsTestsAndEveryVerdictFitsAtBothSizes) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());

  eol::testing::TempDir dir;
  // Self-checks configured on a fresh database: the station starts locked out. The sim's
  // masters are nominal parts (spreads off), so GOOD passes and BAD (soft bond) fails.
  int port = 0;
  const auto station = StartPageStation(
      dir,
      nlohmann::json{
          {"station_id", "page-scan"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "s.sqlite"},
          {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
          {"fixture", {{"driver", "sim"}}},
          // Played at 0.6 x real time: a test lasts about 3 s, long enough to see TESTING.
          {"daq", {{"driver", "sim"}, {"time_scale", 0.6}}},
          {"sim",
           {{"clamp_close_s", 0.05},
            {"clamp_open_s", 0.05},
            {"population", {{"defect_share", 0.0}}},
            {"masters",
             {{{"serial", "MASTER-G"}},
              {{"serial", "MASTER-L"}, {"defective", true}},
              {{"serial", "SCAN-GOOD-1"}},
              {{"serial", "SCAN-BAD-1"}, {"defective", true}}}}}},
          {"self_check", {{"good_master", "MASTER-G"}, {"limit_master", "MASTER-L"}}}},
      &port);
  ASSERT_GT(port, 0);

  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  for (const auto& e : std::filesystem::directory_iterator(artifacts))
    if (e.path().filename().string().rfind("operator-", 0) == 0) std::filesystem::remove(e);
  ChildProcess browser(
      {node, kBrowserDir + "/check_operator.mjs", "http://127.0.0.1:" + std::to_string(port),
       artifacts, "SCAN-LOCKED-1", "MASTER-G", "MASTER-L", "SCAN-GOOD-1", "SCAN-BAD-1"},
      /*merge_stderr=*/false);
  const auto code = browser.Wait(180s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output() << station->output();
  const auto j = nlohmann::json::parse(browser.output());
  const nlohmann::json& states = j["states"];

  // The scanner's field has the focus from the start, after signing in and after a click.
  EXPECT_EQ(j["focus_on_load"], "scan");
  EXPECT_EQ(j["focus_after_sign_in"], "scan");
  EXPECT_EQ(j["focus_after_click"], "scan");
  EXPECT_EQ(j["good_master"], "PASS");
  EXPECT_EQ(j["limit_master"], "FAIL");
  // A master part's FAIL is its self-check passing: not the red bin.
  EXPECT_EQ(j["limit_master_instruction"].get<std::string>().rfind("Master part (self-check)", 0),
            0u)
      << j["limit_master_instruction"];

  const nlohmann::json good = ExpectStoredAsShown(port, j);
  ASSERT_FALSE(good.is_null());
  ExpectLockoutAndInstructions(j);
  ExpectEveryStateFitsAtBothSizes(states);
  ExpectChartAndMeasurements(states, good);
  ExpectLocalTimeWithZone(states);

  EXPECT_TRUE(j["outside_requests"].empty()) << j["outside_requests"];
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  EXPECT_EQ(j["screenshots"].size(), 10u);
  for (const auto& shot : j["screenshots"])
    EXPECT_GT(std::filesystem::file_size(shot.get<std::string>()), 10000u) << shot;
  station->Stop(SIGTERM, 20s);
}

// Every reason code and cause the C++ can emit, as the catalogue names them.
nlohmann::json EmittedReasonKeys() {
  nlohmann::json keys = nlohmann::json::array();
  for (analysis::ReasonCode c : analysis::kAllReasonCodes) keys.push_back(analysis::ToString(c));
  for (std::string_view c : station::cause::kAllCauses) keys.push_back(std::string(c));
  return keys;
}

// Issue 36: a station configured for German speaks German on the operator page: the verdict
// word, the instruction for the reason (a lockout, a FAIL), the reasons in the operator's
// words, with a cue on the new ERROR and FAIL; the engineer's ?lang= shows it in each language,
// never a raw key or a missing word; every reason code and cause gets its instruction in every
// language, and the verdict, the instruction and the failing measurements fit 1280x800.
TEST(OperatorPage, SpeaksTheStationsLanguageAndEveryLanguageHasEveryWord) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());
  eol::testing::TempDir dir;
  const nlohmann::json config = {
      {"station_id", "page-words"},
      {"language", "de"},
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", dir / "s.sqlite"},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}},
      {"sim",
       {{"clamp_close_s", 0.05},
        {"clamp_open_s", 0.05},
        {"population", {{"defect_share", 0.0}}},
        {"masters",
         {{{"serial", "MASTER-G"}},
          {{"serial", "MASTER-L"}, {"defective", true}},
          {{"serial", "WORDS-BAD-1"}, {"defective", true}}}}}},
      {"self_check", {{"good_master", "MASTER-G"}, {"limit_master", "MASTER-L"}}}};
  int port = 0;
  auto station = StartPageStation(dir, config, &port);
  ASSERT_GT(port, 0);
  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  const nlohmann::json keys = EmittedReasonKeys();
  ChildProcess browser(
      {node, kBrowserDir + "/check_words.mjs", "http://127.0.0.1:" + std::to_string(port),
       artifacts, "WORDS-LOCKED-1", "MASTER-G", "MASTER-L", "WORDS-BAD-1", keys.dump(), "de,ja,en"},
      /*merge_stderr=*/false);
  const auto code = browser.Wait(180s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output() << station->output();
  const auto j = nlohmann::json::parse(browser.output());
  const nlohmann::json de = Catalogue("de");

  // The station's language, from its config.
  EXPECT_EQ(j["station_language"], "de");
  EXPECT_EQ(j["error"]["verdict"], de["outcome.ERROR"]);
  EXPECT_EQ(j["error"]["instruction"], de["do.lockout"]);
  EXPECT_EQ(j["error"]["reasons"], nlohmann::json::array({de["what.lockout"]}));
  EXPECT_EQ(j["fail"]["verdict"], de["outcome.FAIL"]);
  const std::string fail_instruction = j["fail"]["instruction"];
  EXPECT_EQ(fail_instruction.rfind(de["do.limit"].get<std::string>(), 0), 0u) << fail_instruction;
  // The audible cue: once for the refused ERROR, once for the FAIL; not for the masters'
  // self-checks (the limit master's FAIL is a passing check).
  EXPECT_EQ(j["fail"]["cues"], "ERROR FAIL");
  EXPECT_TRUE(j["fail"]["raw_keys"].empty()) << j["fail"]["raw_keys"];

  for (const std::string lang : {"de", "ja", "en"}) {
    const nlohmann::json& shown = j["languages"][lang];
    const nlohmann::json words = Catalogue(lang);
    EXPECT_EQ(shown["lang"], lang);
    EXPECT_EQ(shown["missing"], "") << lang;
    EXPECT_EQ(shown["missing_after"], "") << lang;
    EXPECT_TRUE(shown["raw_keys"].empty()) << lang << ": " << shown["raw_keys"];
    EXPECT_EQ(shown["verdict"], words["outcome.FAIL"]) << lang;
    // Verdict, instruction and the failing measurements on screen, the page unscrolled.
    EXPECT_TRUE(shown["verdict_fits"].get<bool>()) << lang;
    EXPECT_TRUE(shown["verdict_inside"].get<bool>()) << lang;
    EXPECT_TRUE(shown["instruction_inside"].get<bool>()) << lang;
    EXPECT_EQ(shown["scrolled"], 0) << lang;
    ASSERT_FALSE(shown["failing"].empty()) << lang << ": no failing measurement shown";
    for (const auto& m : shown["failing"]) {
      EXPECT_TRUE(m["inside"].get<bool>()) << lang << ": " << m;
      const std::string key = "measurement." + m["name"].get<std::string>();
      if (words.contains(key)) {  // a mask's row is named after the mask
        EXPECT_EQ(m["label"], words[key]) << lang;
      }
    }
    EXPECT_EQ(shown["priorities"]["clamped"], "fixture.clamp_left_closed") << lang;
    EXPECT_EQ(shown["priorities"]["legacy"], "legacy") << lang;
    EXPECT_EQ(shown["priorities"]["legacy_what"], words["what.legacy"]) << lang;
    // Every code and cause: that language's instruction and words, on screen.
    for (const auto& key : keys) {
      const nlohmann::json& got = shown["instructions"][key.get<std::string>()];
      EXPECT_EQ(got["instruction"], words["do." + key.get<std::string>()]) << lang << " " << key;
      EXPECT_EQ(got["what"], words["what." + key.get<std::string>()]) << lang << " " << key;
      EXPECT_TRUE(got["inside"].get<bool>()) << lang << " " << key;
    }
  }
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  station->Stop(SIGTERM, 20s);
}

// A station with tokens (any station that listens beyond loopback must have them): the page
// asks for the operator's token when the API answers 401, and the scan then starts the test.
TEST(OperatorPage, AsksForTheOperatorsTokenWhenTheStationHasTokens) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"));
  const std::string node = NodeBinary();
  ASSERT_FALSE(node.empty());
  const std::string token = "op-token-0123456789abcdef";
  eol::testing::TempDir dir;
  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "page-token"},
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", dir / "s.sqlite"},
      {"http",
       {{"listen", "127.0.0.1"},
        {"port", 0},
        {"tokens", {{{"name", "line-op"}, {"role", "operator"}, {"token", token}}}}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}}.dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json", "--web-root",
                        std::string(EOL_SOURCE_DIR) + "/station/web"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  const int port = PortFromReadyLine(station.output());
  ChildProcess browser({node, kBrowserDir + "/check_token.mjs",
                        "http://127.0.0.1:" + std::to_string(port), token, "TOKEN-0001"},
                       /*merge_stderr=*/false);
  const auto code = browser.Wait(120s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output();
  const auto j = nlohmann::json::parse(browser.output());
  EXPECT_FALSE(j["token_row_at_start"].get<bool>());
  EXPECT_NE(j["refused"].get<std::string>().find("TOKEN-0001 not started: this station needs an "
                                                 "operator token"),
            std::string::npos)
      << j["refused"];
  EXPECT_TRUE(j["token_row_after_refusal"].get<bool>());
  EXPECT_EQ(j["focus_after_token"], "scan");
  EXPECT_EQ(j["started"], "TOKEN-0001 started");
  httplib::Client http("127.0.0.1", port);
  const auto res = http.Get("/api/units/TOKEN-0001");
  ASSERT_TRUE(res && res->status == 200);
  const auto tests = nlohmann::json::parse(res->body)["tests"];
  ASSERT_EQ(tests.size(), 1u) << "the refused scan must not have started a test";
  EXPECT_EQ(j["verdict"], tests[0]["outcome"]);
  station.Stop(SIGTERM, 20s);
}

// A station of two motor types (station/daemon/variants.h): the page lists them, and a serial no
// prefix rule claims starts with the type the operator picks, recorded with the unit.
TEST(OperatorPage, OffersTheStationsMotorTypesAndStartsWithThePickedOne) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"));
  const std::string node = NodeBinary();
  ASSERT_FALSE(node.empty());
  eol::testing::TempDir dir;
  const std::string eight = dir / "p8h.json", db = dir / "s.sqlite";
  std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-8pole-heavy.json", eight);
  db::Store::Open(db);  // recipe-approve audits into an existing store
  ChildProcess approve(
      {EOL_BINARY, "recipe-approve", "--recipe", eight, "--by", "qe-test", "--db", db});
  ASSERT_EQ(approve.Wait(60s).value_or(-1), 0) << approve.output();
  std::ofstream(dir / "station.json") << nlohmann::json{
      {"station_id", "page-variants"},
      {"variants",
       {{{"name", "P10"},
         {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
         {"prefixes", {"P10-"}}},
        {{"name", "P8H"}, {"recipe", eight}, {"prefixes", {"P8H-"}}}}},
      {"db", db},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "sim"}}},
      {"daq", {{"driver", "sim"}}}}.dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json", "--web-root",
                        std::string(EOL_SOURCE_DIR) + "/station/web"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  const int port = PortFromReadyLine(station.output());
  ChildProcess browser({node, kBrowserDir + "/check_variant.mjs",
                        "http://127.0.0.1:" + std::to_string(port), "P10", "LINE-0001"},
                       /*merge_stderr=*/false);
  const auto code = browser.Wait(120s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output() << station.output();
  const auto j = nlohmann::json::parse(browser.output());
  EXPECT_EQ(j["options"], nlohmann::json::array({"", "P10", "P8H"})) << j.dump();
  EXPECT_EQ(j["labels"][1], "P10 (pmsm-10pole)") << j.dump();
  EXPECT_EQ(j["started"], "LINE-0001 started") << j.dump();
  httplib::Client http("127.0.0.1", port);
  const auto res = http.Get("/api/units/LINE-0001");
  ASSERT_TRUE(res && res->status == 200);
  const auto tests = nlohmann::json::parse(res->body)["tests"];
  ASSERT_EQ(tests.size(), 1u);
  EXPECT_EQ(tests[0]["recipe"]["id"], "pmsm-10pole") << tests[0].dump();
  station.Stop(SIGTERM, 20s);
}

// Issue 36, live health, in a real browser against a real fixture controller (`eol
// fixture-sim` over Modbus TCP) and the daemon in its own process. check_health.mjs asks for
// each step; the test acts and answers with the time it acted (wall clock, ms).
class HealthSteps {
 public:
  HealthSteps(ChildProcess& browser, std::string dir) : browser_(browser), dir_(std::move(dir)) {}
  // Waits for the browser to ask for `name`, runs `act`, then says when it acted.
  bool Do(const std::string& name, const std::function<void()>& act) {
    if (!browser_.WaitFor(
            [&](const std::string& o) {
              return o.find("step: " + name + "\n") != std::string::npos;
            },
            90s))
      return false;
    const auto acted = std::chrono::duration_cast<std::chrono::milliseconds>(
                           std::chrono::system_clock::now().time_since_epoch())
                           .count();
    act();
    std::ofstream(dir_ + "/" + name + ".done.tmp") << acted;
    std::filesystem::rename(dir_ + "/" + name + ".done.tmp", dir_ + "/" + name + ".done");
    return true;
  }

 private:
  ChildProcess& browser_;
  const std::string dir_;
};

// `eol fixture-sim` on `port` (0: a free one, written to DIR/fixture.port).
std::unique_ptr<ChildProcess> StartFixtureSim(const eol::testing::TempDir& dir, int port) {
  std::filesystem::remove(dir / "fixture.port");
  auto sim = std::make_unique<ChildProcess>(
      std::vector<std::string>{EOL_BINARY, "fixture-sim", "--port", std::to_string(port),
                               "--ready-file", dir / "fixture.port", "--part", "ROTOR-ON-FIXTURE"});
  EXPECT_TRUE(sim->WaitFor(
      [&](const std::string&) { return std::filesystem::exists(dir / "fixture.port"); }, 30s))
      << sim->output();
  return sim;
}

TEST(OperatorPage, FollowsTheFixtureControllerAndShowsALostStationWithin2s) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());
  eol::testing::TempDir dir;
  auto fixture = StartFixtureSim(dir, 0);
  int fixture_port = 0;
  std::ifstream(dir / "fixture.port") >> fixture_port;
  ASSERT_GT(fixture_port, 0);
  nlohmann::json config = {
      {"station_id", "page-health"},
      {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      {"db", dir / "s.sqlite"},
      {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
      {"fixture", {{"driver", "modbus-tcp"}, {"host", "127.0.0.1"}, {"port", fixture_port}}},
      {"daq", {{"driver", "sim"}, {"relay", "external"}}}};  // health.period_ms: 500 (default)
  int port = 0;
  auto station = StartPageStation(dir, config, &port);
  ASSERT_GT(port, 0);
  config["http"]["port"] = port;  // the restarted daemon comes back where the page looks

  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  ChildProcess browser(
      {node, kBrowserDir + "/check_health.mjs", "http://127.0.0.1:" + std::to_string(port),
       dir.path(), artifacts, "HEALTH-1", "HEALTH-2", "HEALTH-3"},
      /*merge_stderr=*/false);
  HealthSteps steps(browser, dir.path());
  ASSERT_TRUE(steps.Do("stop_fixture", [&] { fixture->Stop(SIGKILL, 10s); })) << browser.output();
  ASSERT_TRUE(steps.Do("start_fixture", [&] { fixture = StartFixtureSim(dir, fixture_port); }))
      << browser.output();
  ASSERT_TRUE(steps.Do("freeze_daemon", [&] { kill(station->pid(), SIGSTOP); }))
      << browser.output();
  ASSERT_TRUE(steps.Do("kill_daemon", [&] { station->Stop(SIGKILL, 10s); })) << browser.output();
  ASSERT_TRUE(steps.Do("restart_daemon", [&] {
    int again = 0;
    station = StartPageStation(dir, config, &again);
    EXPECT_EQ(again, port);
  })) << browser.output();
  const auto code = browser.Wait(120s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output() << station->output();
  const std::string last_line =
      browser.output().substr(browser.output().rfind('\n', browser.output().size() - 2) + 1);
  const auto j = nlohmann::json::parse(last_line);

  EXPECT_EQ(j["at_start"]["connection"], "live");
  EXPECT_FALSE(j["at_start"]["start_disabled"].get<bool>());
  EXPECT_TRUE(j["at_start"]["not_ready"].is_null()) << j["at_start"];
  // The controller killed while the station idles: NOT READY with the cause's code and the
  // operator's words, within one health period (500 ms) plus one failed read and the page's
  // own delay; the daemon itself is still live. Back within one period after it returns.
  const nlohmann::json& lost = j["fixture_lost"];
  EXPECT_LE(lost["ms"].get<int>(), 1500) << lost;
  EXPECT_EQ(lost["not_ready"]["code"], "fixture_unreachable") << lost;
  EXPECT_NE(lost["not_ready"]["text"].get<std::string>().find(
                "Fixture controller not answering - call maintenance"),
            std::string::npos)
      << lost;
  EXPECT_EQ(lost["connection"], "live");
  EXPECT_LE(j["fixture_back"]["ms"].get<int>(), 1500) << j["fixture_back"];
  EXPECT_TRUE(j["fixture_back"]["not_ready"].is_null()) << j["fixture_back"];
  // A scan while HEALTH-2 ran: refused with the reason and a cue, still shown after HEALTH-2's
  // verdict (that serial was not tested).
  EXPECT_EQ(j["busy"]["start_status"],
            "HEALTH-2-B not started: busy: a test is running or waiting");
  EXPECT_EQ(j["busy"]["cues"], 1);
  EXPECT_TRUE(j["after_second"]["start_status_problem"].get<bool>()) << j["after_second"];
  // No stale driver text under the next verdict.
  const std::string text = j["after_second"]["page_text"];
  for (const char* stale : {"Connection refused", "fixture unavailable", "NOT READY"})
    EXPECT_EQ(text.find(stale), std::string::npos) << stale << " still on the page:\n" << text;
  // The daemon hung: offline within 2 s, Start disabled, the verdict greyed.
  const nlohmann::json& frozen = j["frozen"];
  EXPECT_LE(frozen["ms"].get<int>(), 2000) << frozen;
  EXPECT_TRUE(frozen["start_disabled"].get<bool>());
  EXPECT_TRUE(frozen["offline_banner"].get<bool>());
  EXPECT_NE(frozen["verdict_filter"].get<std::string>().find("grayscale(1)"), std::string::npos)
      << frozen["verdict_filter"];
  // A scan while it is dead is refused on the page (the serial does not stay in the field).
  EXPECT_EQ(j["refused_offline"]["start_status"], "HEALTH-3 not started: station offline");
  EXPECT_EQ(j["refused_offline"]["scan_field"], "");
  // The daemon back: live, Start enabled; the refusal stays until the next verdict (started
  // by the API, not the page) clears it.
  EXPECT_EQ(j["back"]["connection"], "live");
  EXPECT_FALSE(j["back"]["start_disabled"].get<bool>());
  EXPECT_TRUE(j["back"]["start_status_problem"].get<bool>()) << j["back"];
  // Shift continuity: the restarted daemon's "Last results" and counts come from the store.
  EXPECT_EQ(j["back"]["history"], (nlohmann::json{"HEALTH-2", "HEALTH-1"})) << j["back"];
  std::smatch counts;
  const std::string counts_text = j["back"]["counts"];
  ASSERT_TRUE(std::regex_search(counts_text, counts,
                                std::regex("^Today: PASS ([0-9]+) · FAIL ([0-9]+) · ERROR 0")))
      << counts_text;
  EXPECT_EQ(std::stoi(counts[1]) + std::stoi(counts[2]), 2) << counts_text;
  EXPECT_EQ(j["after_third"]["start_status"], "");
  EXPECT_FALSE(j["after_third"]["start_status_problem"].get<bool>());
  EXPECT_EQ(j["after_third"]["message"], "");
  for (const char* verdict : {"first", "second", "third"})
    EXPECT_TRUE(j[verdict] == "PASS" || j[verdict] == "FAIL") << verdict << ": " << j[verdict];
  std::printf(
      "page: not ready %d ms after the controller was killed, ready %d ms after it "
      "returned; offline %d ms after the daemon hung; live %d ms after its restart\n",
      lost["ms"].get<int>(), j["fixture_back"]["ms"].get<int>(), frozen["ms"].get<int>(),
      j["back"]["ms"].get<int>());
  for (const auto& shot : j["screenshots"])
    EXPECT_GT(std::filesystem::file_size(shot.get<std::string>()), 10000u) << shot;
  station->Stop(SIGTERM, 20s);
}

// Issue 17: the engineer page (GET /engineer, linked from the operator page) against a
// station with stored tests: its capability table is the API's, its charts are the API's
// SVGs with their series, the window and the measurement picker change what is drawn, the
// yield table is GET /api/yield's, the detectability table lists every class, uploads give the
// POD and gap figures; axe-core finds
// nothing serious at 1920x1080 and 1280x800. Screenshots are kept in build/artifacts/.
TEST(EngineerPage, ShowsChartsCapabilityDetectabilityAndFiguresFromFiles) {
  const std::string node = BrowserCheckNode();
  ASSERT_FALSE(node.empty());
  eol::testing::TempDir dir;
  int port = 0;
  const auto station =
      StartPageStation(dir,
                       {{"station_id", "page-engineer"},
                        {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
                        {"db", dir / "s.sqlite"},
                        {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
                        {"fixture", {{"driver", "sim"}}},
                        {"daq", {{"driver", "sim"}}},
                        {"sim",
                         {{"clamp_close_s", 0.02},
                          {"clamp_open_s", 0.02},
                          {"population", {{"defect_share", 0.0}, {"seed", 3}}}}}},
                       &port);
  ASSERT_GT(port, 0);
  httplib::Client http("127.0.0.1", port);
  constexpr int kTests = 12;
  for (int i = 0; i < kTests; ++i)
    ASSERT_FALSE(RunStoredTest(http, "ENG-" + std::to_string(100 + i)).is_null()) << i;
  // What the page must agree with: the API's own capability figures.
  const auto stats = nlohmann::json::parse(http.Get("/api/stats")->body);
  nlohmann::json f0;
  for (const auto& m : stats["recipes"][0]["measurements"])
    if (m["name"] == "resonance_f_hz") f0 = m;
  ASSERT_FALSE(f0.is_null()) << stats;
  const auto detect_reply = http.Get("/api/detectability");
  ASSERT_TRUE(detect_reply) << "GET /api/detectability: "
                            << httplib::to_string(detect_reply.error());
  const auto detect = nlohmann::json::parse(detect_reply->body);

  // Files to upload: a hits table and the gap inputs (a nominal simulation, a unit measured
  // with a channel delay).
  {
    std::ofstream hits(dir / "hits.csv");
    hits << "class,size,hit,f0_hz\n";
    const double sizes[] = {0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45};
    const int hit[] = {0, 0, 1, 0, 1, 1, 1, 1};
    for (int i = 0; i < 8; ++i) hits << "one_magnet," << sizes[i] << "," << hit[i] << ",380\n";
    for (int i = 0; i < 8; ++i) hits << "good,0,0," << 388 + i % 4 << "\n";
  }
  io::WriteFrfCsv(dir / "sim.csv", eol::testing::GapSimulation());
  io::WriteFrfCsv(dir / "meas.csv",
                  eol::testing::GapMeasured({{analysis::EffectKind::kChannelDelay, {6e-6}}}, 3));

  const std::string artifacts = std::filesystem::path(EOL_BINARY).parent_path() / "artifacts";
  std::filesystem::create_directories(artifacts);
  ChildProcess browser(
      {node, kBrowserDir + "/check_engineer.mjs", "http://127.0.0.1:" + std::to_string(port),
       artifacts, "5", dir / "hits.csv", dir / "sim.csv", dir / "meas.csv"},
      /*merge_stderr=*/false);
  const auto code = browser.Wait(300s);
  ASSERT_TRUE(code.has_value()) << "browser did not finish";
  ASSERT_EQ(*code, 0) << browser.output();
  const auto j = nlohmann::json::parse(browser.output());
  EXPECT_EQ(j["link"], "/engineer");
  EXPECT_EQ(j["url"], "http://127.0.0.1:" + std::to_string(port) + "/engineer");

  // The default view: resonance over the last 100 tests (all 12), the API's figures.
  const nlohmann::json& first = j["initial"];
  ASSERT_EQ(first["capability"].size(), 1u) << first;
  const nlohmann::json& row = first["capability"][0];
  EXPECT_EQ(row["name"], "resonance_f_hz");
  EXPECT_EQ(row["n"], f0["n"]);
  for (const char* key : {"cp", "cpk", "pp", "ppk"}) {
    ASSERT_TRUE(f0[key].is_number()) << key << " " << f0;
    EXPECT_NEAR(std::stod(row[key].get<std::string>()), f0[key].get<double>(),
                0.006 * std::abs(f0[key].get<double>()))
        << key;
  }
  const std::string units = std::to_string(f0["n"].get<int>()) + " PASS and FAIL units";
  const std::map<std::string, std::vector<std::string>> want = {
      {"chart-imr",
       {"resonance_f_hz individuals / moving range (I-MR)", "individuals (I chart), " + units,
        "UCL ", "LCL "}},
      {"chart-xbar", {"resonance_f_hz: subgroup means (X-bar chart)", "subgroup ranges (R chart)"}},
      {"chart-hist",
       {"resonance_f_hz: histogram of " + units, "LSL 370 Hz", "USL 420 Hz", "Cpk ", "Ppk "}}};
  for (const auto& [id, words] : want) {
    const nlohmann::json& c = first["charts"][id];
    ASSERT_TRUE(c.is_object()) << id << " not shown: " << first;
    EXPECT_TRUE(c["rendered"].get<bool>()) << id;
    EXPECT_EQ(c["root"], "svg") << id;
    EXPECT_GT(c["paths"].get<int>(), 10) << id << ": no series drawn";
    const std::string all = c["title"].get<std::string>() + "\n" + c["desc"].get<std::string>();
    for (const std::string& w : words) EXPECT_NE(all.find(w), std::string::npos) << id << ": " << w;
  }
  // Yield per day, as GET /api/yield says: 12 units, all PASS at the first test, so no Pareto
  // is asked for (the caption says why).
  const auto yield = nlohmann::json::parse(http.Get("/api/yield?by=day")->body);
  const nlohmann::json& rows = j["yield"]["rows"];
  ASSERT_EQ(rows.size(), yield["groups"].size() + 1) << j["yield"];
  EXPECT_EQ(rows[0]["key"], yield["groups"][0]["key"]);
  EXPECT_TRUE(rows.back()["total"].get<bool>());
  EXPECT_EQ(rows.back()["units"], kTests);
  EXPECT_EQ(rows.back()["first_pass"], "100.0 %");
  EXPECT_EQ(rows.back()["final"], "100.0 %");
  EXPECT_NE(j["yield"]["pareto_caption"].get<std::string>().find("no non-PASS test in the window"),
            std::string::npos)
      << j["yield"];
  EXPECT_EQ(j["yield"]["status"], "12 units, 12 tests");
  // The window: the last 5 tests (all PASS) are 5 units, in the table and on the charts.
  ASSERT_EQ(j["last"]["capability"].size(), 1u);
  EXPECT_EQ(j["last"]["capability"][0]["n"], 5);
  EXPECT_NE(j["last"]["charts"]["chart-imr"]["desc"].get<std::string>().find(
                "individuals (I chart), 5 PASS and FAIL units"),
            std::string::npos)
      << j["last"]["charts"]["chart-imr"];
  EXPECT_NE(j["last"]["charts"]["chart-imr"]["url"].get<std::string>().find("from="),
            std::string::npos);
  // The picker: Q's charts.
  EXPECT_EQ(j["q"]["capability"][0]["name"], "resonance_q");
  for (const char* id : {"chart-imr", "chart-xbar", "chart-hist"})
    EXPECT_NE(j["q"]["charts"][id]["title"].get<std::string>().find("resonance_q"),
              std::string::npos)
        << id << ": " << j["q"]["charts"][id]["title"];
  // Detectability: every class the API reports.
  ASSERT_EQ(j["detectability"].size(), detect["classes"].size());
  for (std::size_t i = 0; i < detect["classes"].size(); ++i) {
    EXPECT_EQ(j["detectability"][i]["defect"], detect["classes"][i]["defect"]);
    EXPECT_EQ(j["detectability"][i]["detectable"],
              detect["classes"][i]["separable"].get<bool>() ? "yes" : "no");
  }
  // Figures from the uploaded files.
  EXPECT_EQ(j["pod_status"], "drawn");
  EXPECT_TRUE(j["pod"]["rendered"].get<bool>());
  EXPECT_EQ(j["pod"]["title"], "POD from hits.csv");
  for (const char* w : {"one_magnet POD", "one_magnet hit/miss", "f0 limit 370.00 Hz", "good (8)"})
    EXPECT_NE(j["pod"]["desc"].get<std::string>().find(w), std::string::npos) << w;
  EXPECT_EQ(j["gap_status"], "drawn");
  EXPECT_TRUE(j["gap"]["rendered"].get<bool>());
  EXPECT_EQ(j["gap"]["title"].get<std::string>().rfind("eol gap: channel_delay", 0), 0u)
      << j["gap"]["title"];
  EXPECT_NE(j["gap"]["title"].get<std::string>().find("meas.csv"), std::string::npos);

  EXPECT_TRUE(j["axe_1920"].empty()) << j["axe_1920"];
  EXPECT_TRUE(j["axe_1280"].empty()) << j["axe_1280"];
  EXPECT_TRUE(j["outside_requests"].empty()) << j["outside_requests"];
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  EXPECT_EQ(j["screenshots"].size(), 3u);
  for (const auto& shot : j["screenshots"])
    EXPECT_GT(std::filesystem::file_size(shot.get<std::string>()), 10000u) << shot;
  station->Stop(SIGTERM, 20s);
}

}  // namespace
}  // namespace eol
