// Teardown findings and the unit report over the HTTP API of a started `eol station` (real
// HTTP on 127.0.0.1, its real SQLite store): only engineers record findings, under their
// token's name; corrections are new findings; GET lists them with the verdict they judged;
// the review counts them; GET /api/units/{serial}/report.pdf is a PDF with the unit's serial,
// verdict and the recipe's masks on the curve (the recipe in use is the test's).
#include <gtest/gtest.h>
#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"
#include "tests/support/station_ready.h"
#include "tests/support/stored_test.h"
#include "tests/support/token_station.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;
using eol::testing::PortFromReadyLine;

constexpr char kOperator[] = "operator-token-0123456789";
constexpr char kEngineer[] = "engineer-token-0123456789";
constexpr char kPdfToText[] = "/usr/bin/pdftotext";

httplib::Headers Bearer(const char* token) {
  return {{"Authorization", std::string("Bearer ") + token}};
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

class TeardownApi : public ::testing::Test {
 protected:
  void SetUp() override {
    std::filesystem::copy_file(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json",
                               dir_ / "pmsm-10pole.json");
    nlohmann::json config =
        testing::TokenStationConfig("td-api", "pmsm-10pole.json", kOperator, kEngineer);
    config["sim"] = {{"clamp_close_s", 0.02},
                     {"clamp_open_s", 0.02},
                     {"population", {{"defect_share", 0.0}, {"seed", 5}}}};
    std::ofstream(dir_ / "station.json") << config.dump();
    station_ = std::make_unique<ChildProcess>(
        std::vector<std::string>{EOL_BINARY, "station", "--config", dir_ / "station.json"});
    ASSERT_TRUE(
        station_->WaitFor([](const std::string& o) { return PortFromReadyLine(o) > 0; }, 30s))
        << station_->output();
    http_ = std::make_unique<httplib::Client>("127.0.0.1", PortFromReadyLine(station_->output()));
    http_->set_read_timeout(120, 0);
  }
  void TearDown() override {
    if (station_) station_->Stop(SIGTERM, 20s);
  }

  httplib::Result Post(const std::string& serial, const char* token, const nlohmann::json& body) {
    return http_->Post("/api/units/" + serial + "/teardown",
                       token ? Bearer(token) : httplib::Headers{}, body.dump(), "application/json");
  }

  eol::testing::TempDir dir_;
  std::unique_ptr<ChildProcess> station_;
  std::unique_ptr<httplib::Client> http_;
};

TEST_F(TeardownApi, EngineersRecordFindingsAndTheReportIsAPdf) {
  std::string why;
  const nlohmann::json t = testing::RunStoredTest(*http_, "TD-1", Bearer(kOperator), &why);
  ASSERT_FALSE(t.is_null()) << why << station_->output();
  const std::string verdict = t["outcome"].get<std::string>();

  const nlohmann::json defective = {{"found", "defective"}, {"note", "cracked magnet"}};
  auto res = Post("TD-1", nullptr, defective);
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 401) << res->body;
  res = Post("TD-1", kOperator, defective);
  EXPECT_EQ(res->status, 403) << res->body;
  res = Post("TD-1", kEngineer, {{"found", "maybe"}});
  EXPECT_EQ(res->status, 400) << res->body;
  EXPECT_TRUE(Has(res->body, "invalid_teardown")) << res->body;
  res = Post("TD-1", kEngineer, {{"found", "defective"}, {"note", 7}});
  EXPECT_EQ(res->status, 400) << res->body;
  res = Post("NEVER-1", kEngineer, defective);
  EXPECT_EQ(res->status, 404) << res->body;
  EXPECT_TRUE(Has(res->body, "unknown_serial")) << res->body;
  auto list = nlohmann::json::parse(http_->Get("/api/units/TD-1/teardown")->body);
  EXPECT_TRUE(list["teardowns"].empty()) << list.dump();  // nothing refused was recorded

  res = Post("TD-1", kEngineer, defective);
  ASSERT_EQ(res->status, 201) << res->body;
  const nlohmann::json first = nlohmann::json::parse(res->body);
  EXPECT_EQ(first["by"], "qe-anna");
  EXPECT_EQ(first["found"], "defective");
  EXPECT_EQ(first["verdict"], verdict);
  res = Post("TD-1", kEngineer, {{"found", "not-defective"}, {"note", "magnet intact"}});
  ASSERT_EQ(res->status, 201) << res->body;
  EXPECT_EQ(nlohmann::json::parse(res->body)["corrects"], first["id"]);

  // `eol teardown` records beside the running station (which holds the store's writer lock).
  const testing::CliRun cli =
      testing::RunEol({"teardown", "--db", dir_ / "s.sqlite", "--serial", "TD-1", "--found",
                       "not-defective", "--by", "Bea", "--note", "second opinion"},
                      true, 60s);
  ASSERT_EQ(cli.code, 0) << cli.out;
  list = nlohmann::json::parse(http_->Get("/api/units/TD-1/teardown")->body);
  ASSERT_EQ(list["teardowns"].size(), 3u) << list.dump();
  EXPECT_EQ(list["teardowns"][0]["note"], "cracked magnet");
  EXPECT_EQ(list["current"]["found"], "not-defective");
  EXPECT_EQ(list["current"]["by"], "Bea");
  const auto review = nlohmann::json::parse(http_->Get("/api/teardown/review")->body);
  EXPECT_EQ(review[verdict == "PASS" ? "confirmed_good" : "false_rejects"].size(), 1u)
      << review.dump();
  EXPECT_EQ(review["confirmed_defective"], 0) << review.dump();

  res = http_->Get("/api/units/TD-1/report.pdf");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200) << res->body;
  EXPECT_EQ(res->get_header_value("Content-Type"), "application/pdf");
  ASSERT_EQ(res->body.rfind("%PDF-", 0), 0u);
  EXPECT_EQ(http_->Get("/api/units/NEVER-1/report.pdf")->status, 404);
  EXPECT_EQ(http_->Get("/api/units/TD-1/report.pdf?test_id=x")->status, 400);

  ASSERT_TRUE(std::filesystem::exists(kPdfToText))
      << "pdftotext is missing: deploy/install-deps.sh --tests installs poppler-utils";
  const std::string pdf = dir_ / "TD-1.pdf";
  std::ofstream(pdf, std::ios::binary) << res->body;
  testing::ChildProcess text({kPdfToText, "-layout", pdf, "-"}, false);
  ASSERT_EQ(text.Wait(60s).value_or(-1), 0) << text.output();
  const std::string words = text.output();
  EXPECT_TRUE(Has(words, "Serial TD-1")) << words;
  EXPECT_TRUE(Has(words, "Verdict: " + verdict)) << words;
  EXPECT_TRUE(Has(words, "td-api")) << words;  // the station
  EXPECT_TRUE(Has(words, "not-defective")) << words;
  EXPECT_TRUE(Has(words, "qe-anna")) << words;
  EXPECT_TRUE(Has(words, "mask re_z_low_band")) << words;  // the recipe in use is the test's
  EXPECT_FALSE(Has(words, "masks not drawn")) << words;
}

}  // namespace
}  // namespace eol
