// The operator page in a real browser (Debian's chromium, driven by playwright-core from
// npm): the daemon runs on its simulators, a test is run, and the page must show the stored
// verdict, the serial and the measured curve against the recipe's mask, then follow a second
// test live. The screenshot is kept in build/artifacts/ for CI.
#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>

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
  EXPECT_EQ(j["first"]["points"], 601) << "the measured curve is not drawn";
  EXPECT_EQ(j["first"]["model"], 1);
  EXPECT_GE(j["first"]["masks"].get<int>(), 1) << "the recipe's mask is not drawn";
  EXPECT_EQ(j["first"]["measurements"], 6);
  // The station runs on its simulators: the page says so, unmissably (issue 14).
  EXPECT_NE(j["first"]["simulation"].get<std::string>().find("SIMULATION"), std::string::npos)
      << j["first"];
  EXPECT_EQ(j["second"]["serial"], "PAGE-0002");
  EXPECT_EQ(j["second"]["connection"], "live");
  EXPECT_TRUE(j["page_errors"].empty()) << j["page_errors"];
  EXPECT_TRUE(std::filesystem::file_size(shot) > 10000) << "no screenshot";
  station.Stop(SIGTERM, 20s);
}

}  // namespace
}  // namespace eol
