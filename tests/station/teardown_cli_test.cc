// Teardown feedback on the command line (issue 36): `eol teardown` records findings per serial
// (append-only, corrections kept) in a real SQLite store; `eol pod --from-db` counts the
// confirmed-defective units as hits and misses and names the false rejects; `eol teach
// --known-bad-from-db` takes the confirmed-defective units as known-bad parts; `eol report`
// writes a PDF whose text (pdftotext, Debian's poppler-utils) holds the serial and verdict.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "db/store.h"
#include "station/daemon/recipe.h"
#include "station/reports/teardown_review.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"
#include "tests/support/pass_records.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using testing::CliRun;

const std::string kRecipe = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";
constexpr char kPdfToText[] = "/usr/bin/pdftotext";

CliRun Eol(std::vector<std::string> args, bool merge_stderr = true) {
  return testing::RunEol(std::move(args), merge_stderr, 300s);
}

bool Has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A tested unit of the shipped recipe: the golden units' values (unit `like`), f0 moved to
// `f0_hz`, stored with `outcome` at minute `minute` of 2026-03-01.
db::TestRecord Unit(const std::string& serial, analysis::Outcome outcome, double f0_hz, int minute,
                    const std::string& hash) {
  db::TestRecord r = testing::PassRecords(hash, 2)[1];
  r.serial = serial;
  r.outcome = outcome;
  r.measurements[0].value = f0_hz;
  r.measurements[0].unit = "Hz";
  r.measurements[0].limit = {380.0, 400.0};
  r.measurements[0].outcome =
      f0_hz < 380.0 ? analysis::MeasurementOutcome::kFail : analysis::MeasurementOutcome::kPass;
  if (outcome == analysis::Outcome::kFail)
    r.reasons.push_back({analysis::ReasonCode::kLimit, "resonance_f_hz below 380"});
  r.station_id = "eol-7";
  r.recipe_id = "pmsm-10pole";
  r.recipe_version = 1;
  r.software_version = "test";
  r.work.operator_id = "op-12";
  char at[32];
  std::snprintf(at, sizeof at, "2026-03-01T08:%02d:00.000Z", minute);
  r.started_at = at;
  std::snprintf(at, sizeof at, "2026-03-01T08:%02d:09.000Z", minute);
  r.finished_at = at;
  return r;
}

// A measured impedance with a resonance at f0, for the report's curve page.
db::Curve Impedance(double f0_hz) {
  db::Curve c;
  c.name = "impedance";
  c.unit = "ohm";
  for (double f = 300.0; f <= 480.0; f += 2.0) {
    const double x = (f - f0_hz) / 6.0;
    c.freq_hz.push_back(f);
    c.re.push_back(0.5 + 0.8 / (1.0 + x * x));
    c.im.push_back(2.0 * M_PI * f * 2e-3 - 0.8 * x / (1.0 + x * x));
  }
  return c;
}

class TeardownCli : public ::testing::Test {
 protected:
  void SetUp() override {
    hash_ = station::LoadRecipe(kRecipe).hash;
    auto store = db::Store::Open(db_);
    std::vector<db::TestRecord> units = {
        Unit("KB-LOW", analysis::Outcome::kFail, 370.0, 1, hash_),
        Unit("KB-HIDDEN", analysis::Outcome::kPass, 390.0, 2, hash_),
        Unit("FR-1", analysis::Outcome::kFail, 379.0, 3, hash_),
        Unit("OTHER-R", analysis::Outcome::kFail, 371.0, 4, std::string(64, 'a')),
        Unit("KB-ERR", analysis::Outcome::kError, 390.0, 5, hash_),
        Unit("GOOD-1", analysis::Outcome::kPass, 390.0, 6, hash_)};
    units[2].curves.push_back(Impedance(379.0));
    store->InsertAll(units);
  }
  std::string Db() const { return db_; }

  eol::testing::TempDir dir_;
  std::string db_ = dir_ / "s.sqlite";
  std::string hash_;
};

TEST_F(TeardownCli, RecordsListsAndKeepsCorrections) {
  CliRun r = Eol({"teardown", "--db", Db(), "--serial", "FR-1", "--found", "defective", "--by",
                  "Ada", "--note", "magnet loose?"});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(Has(r.out, "defective (judged test #3, FAIL) by Ada: magnet loose?")) << r.out;
  r = Eol({"teardown", "--db", Db(), "--serial", "FR-1", "--found", "not-defective", "--by", "Bob",
           "--note", "magnet fine, re-measured"});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(Has(r.out, "corrects #1")) << r.out;
  EXPECT_TRUE(Has(r.out, "false reject")) << r.out;

  r = Eol({"teardown", "--db", Db(), "--serial", "FR-1", "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["teardowns"].size(), 2u) << r.out;
  EXPECT_EQ(j["teardowns"][0]["found"], "defective");
  EXPECT_EQ(j["teardowns"][0]["by"], "Ada");
  EXPECT_EQ(j["teardowns"][1]["found"], "not-defective");
  EXPECT_EQ(j["teardowns"][1]["by"], "Bob");
  EXPECT_EQ(j["teardowns"][1]["corrects"], j["teardowns"][0]["id"]);
  EXPECT_EQ(j["teardowns"][1]["verdict"], "FAIL");
  EXPECT_FALSE(j["teardowns"][1]["at"].get<std::string>().empty());

  r = Eol({"teardown", "--db", Db(), "--serial", "GOOD-1"});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_TRUE(Has(r.out, "GOOD-1: no teardown finding")) << r.out;
}

TEST_F(TeardownCli, RefusesWhatItCannotRecord) {
  CliRun r =
      Eol({"teardown", "--db", Db(), "--serial", "NEVER-1", "--found", "defective", "--by", "Ada"});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(Has(r.out, "no finished test of that serial")) << r.out;
  r = Eol({"teardown", "--db", Db(), "--serial", "KB-LOW", "--found", "broken", "--by", "Ada"});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(Has(r.out, "--found")) << r.out;
  r = Eol({"teardown", "--db", Db(), "--serial", "KB-LOW", "--found", "defective"});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(Has(r.out, "--by")) << r.out;
  r = Eol({"teardown", "--db", Db(), "--serial", "KB-LOW", "--by", "Ada"});
  EXPECT_EQ(r.code, 2) << r.out;  // --by without --found
  EXPECT_TRUE(db::Store::Open(Db(), db::Store::Role::kReadOnly)->CurrentTeardowns().empty());
}

// Findings of five serials: KB-LOW and OTHER-R defective after FAIL (hits), KB-HIDDEN
// defective after PASS (a miss), FR-1 not defective after FAIL (a false reject), KB-ERR
// defective after ERROR (no verdict).
void RecordFindings(const std::string& db) {
  const std::vector<std::pair<std::string, std::string>> findings = {{"KB-LOW", "defective"},
                                                                     {"KB-HIDDEN", "defective"},
                                                                     {"FR-1", "not-defective"},
                                                                     {"OTHER-R", "defective"},
                                                                     {"KB-ERR", "defective"}};
  for (const auto& [serial, found] : findings) {
    const CliRun r =
        Eol({"teardown", "--db", db, "--serial", serial, "--found", found, "--by", "Ada"});
    ASSERT_EQ(r.code, 0) << serial << ": " << r.out;
  }
}

TEST_F(TeardownCli, PodFromTheStoreCountsHitsMissesAndFalseRejects) {
  CliRun r = Eol({"pod", "--from-db", Db()});
  EXPECT_EQ(r.code, 1) << r.out;  // nothing confirmed yet
  EXPECT_TRUE(Has(r.out, "no confirmed-defective unit")) << r.out;
  RecordFindings(Db());
  r = Eol({"pod", "--from-db", Db(), "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json t = nlohmann::json::parse(r.out)["teardown"];
  EXPECT_EQ(t["confirmed_defective"], 3);
  ASSERT_EQ(t["hits"].size(), 2u);
  EXPECT_EQ(t["hits"][0]["serial"], "KB-LOW");
  EXPECT_EQ(t["hits"][1]["serial"], "OTHER-R");
  ASSERT_EQ(t["misses"].size(), 1u);
  EXPECT_EQ(t["misses"][0]["serial"], "KB-HIDDEN");
  ASSERT_EQ(t["false_rejects"].size(), 1u);
  EXPECT_EQ(t["false_rejects"][0]["serial"], "FR-1");
  ASSERT_EQ(t["no_verdict"].size(), 1u);
  EXPECT_EQ(t["no_verdict"][0]["verdict"], "ERROR");
  EXPECT_NEAR(t["pod"].get<double>(), 2.0 / 3.0, 1e-12);
  // The exact lower bound p solves P(X >= 2 | n = 3, p) = 0.05: 3p^2 - 2p^3 = 0.05.
  const double p = t["pod_lower"].get<double>();
  EXPECT_NEAR(3 * p * p - 2 * p * p * p, 0.05, 1e-9) << p;
  r = Eol({"pod", "--from-db", Db()});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_TRUE(Has(r.out, "2 hit(s) (FAIL), 1 miss(es) (PASS)")) << r.out;
  EXPECT_TRUE(Has(r.out, "miss: KB-HIDDEN")) << r.out;
  EXPECT_TRUE(Has(r.out, "false reject: FR-1")) << r.out;
  r = Eol({"pod"});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_TRUE(Has(r.out, "--hits or --from-db")) << r.out;
}

TEST(TeardownReview, BinomialLowerBoundMatchesClosedForms) {
  // All n caught: the bound is (1 - confidence)^(1/n).
  EXPECT_NEAR(station::BinomialLowerBound(3, 3, 0.95), std::pow(0.05, 1.0 / 3.0), 1e-9);
  EXPECT_NEAR(station::BinomialLowerBound(29, 29, 0.95), std::pow(0.05, 1.0 / 29.0), 1e-9);
  // One of n: 1 - (1 - p)^n = 0.05.
  EXPECT_NEAR(station::BinomialLowerBound(1, 10, 0.95), 1.0 - std::pow(0.95, 0.1), 1e-9);
  EXPECT_EQ(station::BinomialLowerBound(0, 10, 0.95), 0.0);
  EXPECT_THROW(station::BinomialLowerBound(4, 3, 0.95), std::invalid_argument);
  EXPECT_THROW(station::BinomialLowerBound(1, 3, 1.0), std::invalid_argument);
}

TEST_F(TeardownCli, TeachTakesConfirmedDefectiveUnitsAsKnownBad) {
  const nlohmann::json golden = testing::PassRecords(hash_, 10);
  const std::string golden_path = dir_ / "golden.json";
  std::ofstream(golden_path) << golden.dump();
  const std::vector<std::string> teach = {"teach",
                                          "--recipe",
                                          kRecipe,
                                          "--out",
                                          dir_ / "t.json",
                                          "--force",
                                          "--allow-few-units",
                                          "--golden",
                                          golden_path,
                                          "--known-bad-from-db",
                                          Db(),
                                          "--json"};
  CliRun r = Eol(teach, false);
  EXPECT_EQ(r.code, 2) << r.out;  // no finding yet
  RecordFindings(Db());
  r = Eol(teach, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_TRUE(j.contains("known_bad")) << r.out;
  EXPECT_EQ(j["known_bad"]["units"], 2) << r.out;  // KB-LOW and KB-HIDDEN
  const std::string skipped = j["known_bad_skipped"].dump();
  EXPECT_TRUE(Has(skipped, "OTHER-R")) << skipped;
  EXPECT_TRUE(Has(skipped, "KB-ERR")) << skipped;
  EXPECT_FALSE(Has(skipped, "FR-1")) << skipped;  // not defective: never a known-bad unit
  const std::string escapes = j["known_bad"]["escapes"].dump();
  EXPECT_TRUE(Has(escapes, "KB-HIDDEN")) << escapes;
  EXPECT_FALSE(Has(escapes, "KB-LOW")) << escapes;
}

std::string PdfText(const std::string& pdf) {
  testing::ChildProcess p({kPdfToText, "-layout", pdf, "-"}, false);
  const auto code = p.Wait(60s);
  EXPECT_EQ(code.value_or(-1), 0) << p.output();
  return p.output();
}

TEST_F(TeardownCli, ReportIsAPdfWithTheSerialVerdictMeasurementsAndFindings) {
  ASSERT_TRUE(std::filesystem::exists(kPdfToText))
      << "pdftotext is missing: deploy/install-deps.sh --tests installs poppler-utils";
  ASSERT_EQ(Eol({"teardown", "--db", Db(), "--serial", "FR-1", "--found", "not-defective", "--by",
                 "Ada", "--note", "magnet fine"})
                .code,
            0);
  const std::string pdf = dir_ / "FR-1.pdf";
  CliRun r = Eol({"report", "--db", Db(), "--serial", "FR-1", "--out", pdf, "--recipe", kRecipe});
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(pdf, std::ios::binary);
  std::string head(5, '\0');
  in.read(head.data(), 5);
  EXPECT_EQ(head, "%PDF-");
  const std::string text = PdfText(pdf);
  EXPECT_TRUE(Has(text, "Serial FR-1")) << text;
  EXPECT_TRUE(Has(text, "Verdict: FAIL")) << text;
  EXPECT_TRUE(Has(text, "resonance_f_hz below 380")) << text;
  EXPECT_TRUE(Has(text, "380 .. 400")) << text;
  EXPECT_TRUE(Has(text, hash_)) << text;
  EXPECT_TRUE(Has(text, "op-12")) << text;
  EXPECT_TRUE(Has(text, "2026-03-01T08:03:00.000Z")) << text;
  EXPECT_TRUE(Has(text, "not-defective (judged test #3) by Ada: magnet fine")) << text;
  EXPECT_TRUE(Has(text, "|Z| measured and fitted")) << text;  // the curve page's chart

  // A unit without a curve says so; PASS is printed as such.
  r = Eol({"report", "--db", Db(), "--serial", "GOOD-1", "--out", dir_ / "g.pdf", "--json"}, false);
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json written = nlohmann::json::parse(r.out);
  EXPECT_EQ(written["outcome"], "PASS");
  EXPECT_EQ(written["test_id"], 6);
  EXPECT_EQ(written["bytes"], std::filesystem::file_size(dir_ / "g.pdf"));
  const std::string good = PdfText(dir_ / "g.pdf");
  EXPECT_TRUE(Has(good, "Verdict: PASS")) << good;
  EXPECT_TRUE(Has(good, "stored no impedance curve")) << good;
  EXPECT_TRUE(Has(good, "none recorded")) << good;

  r = Eol({"report", "--db", Db(), "--serial", "NEVER-1", "--out", dir_ / "n.pdf"});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_TRUE(Has(r.out, "NEVER-1 has no finished test")) << r.out;
  r = Eol({"report", "--db", Db(), "--serial", "FR-1", "--test-id", "1", "--out", dir_ / "x.pdf"});
  EXPECT_EQ(r.code, 1) << r.out;  // test 1 is KB-LOW's
  EXPECT_FALSE(std::filesystem::exists(dir_ / "n.pdf"));
  EXPECT_FALSE(std::filesystem::exists(dir_ / "x.pdf"));
}

}  // namespace
}  // namespace eol
