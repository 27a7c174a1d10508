// The operator page in a real browser (Debian's chromium, driven by playwright-core from
// npm): the daemon runs on its simulators, a test is run, and the page must show the stored
// verdict, the serial and the measured curve against the recipe's mask, then follow a second
// test live; and a scanner typing serials into the page starts tests whose verdicts must fit
// and be readable at two screen sizes, with axe-core in the page. Screenshots are kept in
// build/artifacts/ for CI.
#include <gtest/gtest.h>
#include <httplib.h>

#include <cmath>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "../support/child_process.h"
#include "../support/station_ready.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

const std::string kBrowserDir = std::string(EOL_SOURCE_DIR) + "/tests/peers/browser";

using eol::testing::PortFromReadyLine;

std::string NodeBinary() {
  for (const char* p : {"/usr/local/bin/node", "/usr/bin/node", "/usr/bin/nodejs"})
    if (std::filesystem::exists(p)) return p;
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

TEST(OperatorPage, ShowsVerdictCurveAndFollowsTestsLive) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is a declared test dependency (deploy/install-deps.sh --tests)";
  const std::string node = NodeBinary();
  ASSERT_FALSE(node.empty()) << "node.js is a declared test dependency";
  ASSERT_TRUE(std::filesystem::exists(kBrowserDir + "/node_modules/playwright-core"))
      << "run `npm ci` in tests/peers/browser (deploy/run-tests.sh does)";

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

// The recipe's instructions (issue 17): the page shows the one for the outcome.
nlohmann::json ShippedInstructions() {
  std::ifstream in(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  return nlohmann::json::parse(in).at("instructions");
}

// Issue 17: a keyboard-wedge scanner starts tests from the page; the verdict fits its box
// and stays large at 1280x800 and 1920x1080; ERROR is not dressed as FAIL; the recipe's
// instruction stands above the reason; the chart draws the model on top and every limit the
// verdict used; the lockout and the simulation are banners; times are local with their zone;
// axe-core finds nothing serious. Screenshots of each state at both sizes are kept.
TEST(OperatorPage, ScannerStartsTestsAndEveryVerdictFitsAtBothSizes) {
  ASSERT_TRUE(std::filesystem::exists("/usr/bin/chromium"))
      << "Debian's chromium is a declared test dependency (deploy/install-deps.sh --tests)";
  const std::string node = NodeBinary();
  ASSERT_FALSE(node.empty()) << "node.js is a declared test dependency";
  ASSERT_TRUE(std::filesystem::exists(kBrowserDir + "/node_modules/axe-core/axe.min.js"))
      << "run `npm ci` in tests/peers/browser (deploy/run-tests.sh does)";

  eol::testing::TempDir dir;
  // Self-checks configured on a fresh database: the station starts locked out. The sim's
  // masters are nominal parts (spreads off), so GOOD passes and BAD (soft bond) fails.
  std::ofstream(dir / "station.json") << nlohmann::json{
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
      {"self_check",
       {{"good_master", "MASTER-G"},
        {"limit_master", "MASTER-L"}}}}.dump();
  ChildProcess station({EOL_BINARY, "station", "--config", dir / "station.json", "--web-root",
                        std::string(EOL_SOURCE_DIR) + "/station/web"});
  ASSERT_TRUE(station.WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
      << station.output();
  const int port = PortFromReadyLine(station.output());

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
  ASSERT_EQ(*code, 0) << browser.output() << station.output();
  const auto j = nlohmann::json::parse(browser.output());
  const nlohmann::json instructions = ShippedInstructions();
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
  ASSERT_FALSE(good.is_null()) << "the scanned serial was not tested";
  EXPECT_EQ(good["outcome"], "PASS");
  EXPECT_EQ(states["pass"]["verdict"], "PASS");
  EXPECT_EQ(good["operator_id"], "op-17");
  EXPECT_EQ(good["shift"], "B");
  EXPECT_NE(states["pass"]["tested"].get<std::string>().find("operator op-17 · shift B"),
            std::string::npos)
      << states["pass"]["tested"];
  EXPECT_EQ(stored("SCAN-BAD-1")["outcome"], "FAIL");
  EXPECT_EQ(states["fail"]["verdict"], "FAIL");
  EXPECT_TRUE(stored("SCAN-LOCKED-1").is_null()) << "a refused serial is not stored";

  // Lockout: a banner; the refused serial is ERROR with the recipe's instruction above the
  // technical reason; ERROR's lamp is not FAIL's.
  EXPECT_NE(states["lockout"]["lockout"].get<std::string>().find("LOCKED OUT"), std::string::npos);
  EXPECT_EQ(states["error"]["sizes"]["1280x800"]["verdict"]["text"], "ERROR");
  EXPECT_EQ(states["error"]["instruction"], instructions["error"]);
  ASSERT_FALSE(states["error"]["reasons"].empty());
  EXPECT_NE(states["error"]["reasons"][0].get<std::string>().find("locked out"), std::string::npos);
  EXPECT_EQ(states["fail"]["instruction"], instructions["fail"]);
  EXPECT_EQ(states["pass"]["instruction"], "");
  for (const char* size : {"words_1280x800", "words_1920x1080"}) {
    const nlohmann::json& w = j[size];
    EXPECT_NE(w["ERROR"]["background"], w["FAIL"]["background"]) << size;
    EXPECT_NE(w["ABORTED"]["background"], w["FAIL"]["background"]) << size;
    // Every word the lamp can show fits its box (scrollWidth <= clientWidth).
    for (const char* word : {"PASS", "FAIL", "ERROR", "ABORTED", "TESTING"})
      EXPECT_TRUE(w[word]["fits"].get<bool>()) << size << " " << word << ": " << w[word];
  }

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

  EXPECT_TRUE(j["outside_requests"].empty()) << j["outside_requests"];
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  EXPECT_EQ(j["screenshots"].size(), 10u);
  for (const auto& shot : j["screenshots"])
    EXPECT_GT(std::filesystem::file_size(shot.get<std::string>()), 10000u) << shot;
  station.Stop(SIGTERM, 20s);
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

}  // namespace
}  // namespace eol
