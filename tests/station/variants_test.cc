// Variants (issue 36, station/daemon/variants.h): the config's "variants" parsed naming the JSON
// path; the selection rules one by one; a proposal refused at start naming it; and end to end
// through the daemon's HTTP start and through the line PLC's variant register (pymodbus on
// 127.0.0.1 against the real PLC server), with two recipes: the shipped pmsm-10pole and a
// copy of the shipped pmsm-8pole-heavy proposal approved by `eol recipe-approve`. Real SQLite
// file, the sim bench.
#include "station/daemon/variants.h"

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <thread>

#include "db/store.h"
#include "drivers/io/json_config.h"
#include "station/daemon/config.h"
#include "station/daemon/plc/plc_map.h"
#include "station/daemon/recipe.h"
#include "station/daemon/station.h"
#include "tests/peers/modbus_peer_support.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"
#include "tests/support/wait_until.h"

// After Eigen: <resolv.h> (through httplib) defines _res, a parameter name in Eigen.
#include <httplib.h>

namespace eol::station {
namespace {

using namespace std::chrono_literals;
namespace peers = eol::testing::modbus_peers;

const std::string kTenPole = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";
const std::string kEightPole = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-8pole-heavy.json";

// The message ParseStationConfig throws for `j`, or "accepted".
std::string ConfigError(const nlohmann::json& j) {
  try {
    ParseStationConfig(j, "test", "/etc/eol");
  } catch (const io::ConfigError& e) {
    return e.what();
  }
  return "accepted";
}

nlohmann::json Base() {
  return {{"db", "/tmp/x.sqlite"}, {"fixture", {{"driver", "sim"}}}, {"daq", {{"driver", "sim"}}}};
}

nlohmann::json WithVariants(nlohmann::json variants) {
  nlohmann::json j = Base();
  j["variants"] = std::move(variants);
  return j;
}

TEST(VariantConfig, ParsedWithPathsRelativeToTheConfig) {
  nlohmann::json j = WithVariants(
      {{{"name", "P10"}, {"recipe", "r/p10.json"}, {"plc_code", 1}, {"prefixes", {"P10-"}}},
       {{"name", "P8H"}, {"recipe", "/abs/p8.json"}, {"patterns", {"8H[0-9]{4}"}}}});
  const StationConfig c = ParseStationConfig(j, "test", "/etc/eol");
  ASSERT_EQ(c.variants.size(), 2u);
  EXPECT_EQ(c.variants[0].recipe_path, "/etc/eol/r/p10.json");
  EXPECT_EQ(c.variants[0].plc_code, 1);
  EXPECT_EQ(c.variants[1].recipe_path, "/abs/p8.json");
  EXPECT_EQ(c.variants[1].plc_code, 0) << "no plc_code: the PLC cannot pick it";
  EXPECT_EQ(c.recipe_path, "/etc/eol/r/p10.json") << "the first variant's, until the first unit";

  // The one-recipe config is unchanged: no variants.
  nlohmann::json one = Base();
  one["recipe"] = "r/p10.json";
  const StationConfig single = ParseStationConfig(one, "test", "/etc/eol");
  EXPECT_TRUE(single.variants.empty());
  EXPECT_EQ(single.recipe_path, "/etc/eol/r/p10.json");
}

TEST(VariantConfig, EveryErrorNamesTheJsonPath) {
  const nlohmann::json p10 = {
      {"name", "P10"}, {"recipe", "a.json"}, {"plc_code", 1}, {"prefixes", {"P10-"}}};
  nlohmann::json both = WithVariants({p10});
  both["recipe"] = "a.json";
  EXPECT_EQ(ConfigError(both).rfind("config test: /recipe: give either \"recipe\"", 0), 0u)
      << ConfigError(both);
  EXPECT_EQ(ConfigError(WithVariants(nlohmann::json::array())),
            "config test: /variants: must be a non-empty array of variants");
  EXPECT_EQ(ConfigError(WithVariants({{{"name", "P 10"}, {"recipe", "a.json"}}}))
                .rfind("config test: /variants/0/name: must be 1 to 32 characters", 0),
            0u);
  EXPECT_EQ(
      ConfigError(WithVariants({p10, {{"name", "P8"}, {"recipe", "b.json"}, {"plc_code", 0}}}))
          .rfind("config test: /variants/1/plc_code: must be in [1, 65535]", 0),
      0u);
  EXPECT_EQ(
      ConfigError(WithVariants({p10, {{"name", "P8"}, {"recipe", "b.json"}, {"plc_code", 1}}})),
      "config test: /variants/1/plc_code: 1 is already variant 'P10''s code");
  EXPECT_EQ(ConfigError(WithVariants({p10, {{"name", "P10"}, {"recipe", "b.json"}}})),
            "config test: /variants/1/name: 'P10' is already variant 0's name");
  EXPECT_EQ(
      ConfigError(
          WithVariants({p10, {{"name", "P8"}, {"recipe", "b.json"}, {"prefixes", {"P1"}}}})),
      "config test: /variants/1/prefixes/0: 'P1' and variant 'P10''s prefix 'P10-' would both "
      "match a serial starting with the longer one");
  EXPECT_EQ(
      ConfigError(WithVariants({{{"name", "P8"}, {"recipe", "b.json"}, {"patterns", {"(8H"}}}}))
          .rfind("config test: /variants/0/patterns/0: not a regular expression (", 0),
      0u);
  EXPECT_EQ(ConfigError(WithVariants({{{"name", "P8"}, {"recipe", "b.json"}, {"prefixes", {""}}}})),
            "config test: /variants/0/prefixes/0: must be a non-empty string");
  EXPECT_EQ(ConfigError(WithVariants({{{"name", "P8"}, {"recipe", "b.json"}, {"prefix", "P8"}}}))
                .rfind("config test: /variants/0/prefix", 0),
            0u)
      << "an unknown key is refused, not ignored";
  EXPECT_EQ(
      ConfigError(WithVariants({{{"name", "P8"}}})).rfind("config test: /variants/0/recipe", 0),
      0u);
}

std::vector<VariantConfig> TwoVariants() {
  return ParseVariants({{{"name", "P10"},
                         {"recipe", "p10.json"},
                         {"plc_code", 1},
                         {"prefixes", {"P10-"}},
                         {"patterns", {"10P[0-9]{4}"}}},
                        {{"name", "P8H"},
                         {"recipe", "p8.json"},
                         {"plc_code", 2},
                         {"prefixes", {"P8H-"}},
                         {"patterns", {"[0-9]{4}-8H"}}},
                        {{"name", "SPARE"}, {"recipe", "s.json"}, {"patterns", {"[0-9]{4}-8.*"}}}},
                       "/variants", [](const std::string& p) { return p; });
}

TEST(VariantSelection, TheSerialsPrefixOrWholePatternPicks) {
  const auto v = TwoVariants();
  VariantSelection s = SelectVariant(v, "P10-000123", {});
  ASSERT_EQ(s.refusal, VariantRefusal::kNone) << s.why;
  EXPECT_EQ(v[s.index].name, "P10");
  EXPECT_EQ(s.by, "prefix 'P10-'");
  s = SelectVariant(v, "10P0042", {});
  ASSERT_EQ(s.refusal, VariantRefusal::kNone) << s.why;
  EXPECT_EQ(s.by, "pattern '10P[0-9]{4}'");
  // A pattern matches the whole serial, never a part of it.
  s = SelectVariant(v, "X10P0042", {});
  EXPECT_EQ(s.refusal, VariantRefusal::kNoRule);
  EXPECT_EQ(s.why,
            "serial 'X10P0042' matches no variant's part-number prefix or pattern and no variant "
            "was chosen (variants: P10, P8H, SPARE); choose the variant or check the serial");
  // Two variants' rules: refused, naming both, never the first one silently.
  s = SelectVariant(v, "1234-8H", {});
  EXPECT_EQ(s.refusal, VariantRefusal::kNoRule);
  EXPECT_EQ(s.why,
            "serial '1234-8H' matches several variants (P8H by its pattern '[0-9]{4}-8H', SPARE by "
            "its pattern '[0-9]{4}-8.*'); choose the variant");
}

// A pattern that backtracks beyond its match limit refuses the unit at once, naming the
// pattern: it neither hangs the station nor counts as "no match" (which would let another
// variant's rule or the operator's choice stand).
TEST(VariantSelection, APatternThatBacktracksTooMuchRefusesTheUnitQuickly) {
  const auto v = ParseVariants({{{"name", "A"}, {"recipe", "a.json"}, {"patterns", {"(a+)+[bc]"}}},
                                {{"name", "B"}, {"recipe", "b.json"}, {"prefixes", {"aaa"}}}},
                               "/variants", [](const std::string& p) { return p; });
  const std::string serial(60, 'a');
  const auto t0 = std::chrono::steady_clock::now();
  VariantSelection s = SelectVariant(v, serial, {"B", 0});
  EXPECT_LT(std::chrono::steady_clock::now() - t0, 2s);
  EXPECT_EQ(s.refusal, VariantRefusal::kNoRule);
  EXPECT_EQ(s.why, "variant 'A''s pattern '(a+)+[bc]' exceeded its match limit on serial '" +
                       serial + "' (it backtracks too much); simplify the pattern");
  s = SelectVariant(v, "aaab", {});  // matched within the limit: A's pattern and B's prefix
  EXPECT_EQ(s.refusal, VariantRefusal::kNoRule);
  EXPECT_NE(s.why.find("matches several variants"), std::string::npos) << s.why;
}

TEST(VariantSelection, TheOperatorOrThePlcNamesItAndAContradictingRuleRefuses) {
  const auto v = TwoVariants();
  VariantSelection s = SelectVariant(v, "ANY-1", {"P8H", 0});
  ASSERT_EQ(s.refusal, VariantRefusal::kNone) << s.why;
  EXPECT_EQ(v[s.index].name, "P8H");
  EXPECT_EQ(s.by, "operator");
  s = SelectVariant(v, "ANY-1", {"", 2});
  ASSERT_EQ(s.refusal, VariantRefusal::kNone) << s.why;
  EXPECT_EQ(v[s.index].name, "P8H");
  EXPECT_EQ(s.by, "plc code 2");
  // A named variant agreeing with the serial's rule, and resolving two rules.
  s = SelectVariant(v, "P8H-7", {"P8H", 0});
  EXPECT_EQ(s.refusal, VariantRefusal::kNone) << s.why;
  s = SelectVariant(v, "1234-8H", {"SPARE", 0});
  EXPECT_EQ(s.refusal, VariantRefusal::kConflict) << "P8H's rule claims it too";

  s = SelectVariant(v, "P10-1", {"P8", 0});
  EXPECT_EQ(s.refusal, VariantRefusal::kUnknown);
  EXPECT_EQ(s.why, "unknown variant 'P8' (this station's: P10, P8H, SPARE)");
  s = SelectVariant(v, "P10-1", {"", 9});
  EXPECT_EQ(s.refusal, VariantRefusal::kUnknown);
  EXPECT_EQ(s.why, "the PLC's variant register holds 9, no variant's code (codes: 1 P10, 2 P8H)");
  s = SelectVariant(v, "P10-1", {"", 2});
  EXPECT_EQ(s.refusal, VariantRefusal::kConflict);
  EXPECT_EQ(s.why,
            "serial 'P10-1' is part number of variant P10 by its prefix 'P10-', but variant 'P8H' "
            "was chosen (plc code 2); check the part and the choice");
  s = SelectVariant(v, "ANY-1", {"P10", 2});
  EXPECT_EQ(s.refusal, VariantRefusal::kConflict);
  EXPECT_EQ(s.why, "the operator chose variant 'P10', the PLC's register P8H");
  EXPECT_STREQ(ToString(VariantRefusal::kConflict), "variant_conflict");
}

// A station of two variants: P10 (the shipped ten-pole recipe, prefix "P10-", PLC code 1) and
// P8H (a copy of the shipped eight-pole proposal, approved here by `eol recipe-approve`).
class TwoRecipeStation : public ::testing::Test {
 protected:
  void SetUp() override {
    db::Store::Open(db_path_);  // recipe-approve audits into an existing store
    std::filesystem::copy_file(kEightPole, eight_pole_);
    std::filesystem::copy_file(kTenPole, ten_pole_);  // ChangeRecipe writes over it
    const auto run = eol::testing::RunEol({"recipe-approve", "--recipe", eight_pole_, "--by",
                                           "qe-test", "--note", "variants test", "--db", db_path_},
                                          true, 120s);
    ASSERT_EQ(run.code, 0) << run.out;
    ASSERT_TRUE(LoadRecipe(eight_pole_).Approved());
  }
  void TearDown() override {
    if (!station_) return;
    station_->RequestStop("test over");
    if (serve_.joinable()) serve_.join();
  }

  nlohmann::json Config(const std::string& eight_pole) const {
    return {{"station_id", "variants"},
            {"variants",
             {{{"name", "P10"}, {"recipe", ten_pole_}, {"plc_code", 1}, {"prefixes", {"P10-"}}},
              {{"name", "P8H"}, {"recipe", eight_pole}, {"plc_code", 2}, {"prefixes", {"P8H-"}}}}},
            {"db", db_path_},
            {"http", {{"listen", "127.0.0.1"}, {"port", 0}}},
            {"plc", {{"listen", "127.0.0.1"}, {"port", 0}, {"unit_id", 1}}},
            {"fixture", {{"driver", "sim"}}},
            {"daq", {{"driver", "sim"}}},
            {"sim",
             {{"clamp_close_s", 0.02},
              {"clamp_open_s", 0.02},
              {"population", {{"defect_share", 0.0}}}}}};
  }

  void Start() {
    station_ = std::make_unique<Station>(ParseStationConfig(Config(eight_pole_), "test", ""));
    station_->StartHttp();
    station_->StartPlc();
    serve_ = std::thread([this] { station_->Serve(); });
  }

  // POST /api/tests, retried while the previous test is still finishing ("busy").
  httplib::Result Post(const nlohmann::json& body) {
    httplib::Client http("127.0.0.1", station_->http_port());
    http.set_read_timeout(10, 0);
    std::optional<httplib::Result> res;
    eol::testing::WaitUntil([&] {
      res.emplace(http.Post("/api/tests", body.dump(), "application/json"));
      return !*res || (*res)->status != 409 || (*res)->body.find("\"busy\"") == std::string::npos;
    });
    return std::move(*res);
  }

  // Waits (up to 120 s) until `n` records are stored; returns them newest first.
  std::vector<db::TestRecord> Stored(std::size_t n) const {
    std::vector<db::TestRecord> tests;
    eol::testing::WaitUntil(
        [&] {
          tests = db::Store::Open(db_path_, db::Store::Role::kReader)->Tests(db::TestQuery{});
          return tests.size() >= n;
        },
        120s, 50ms);
    return tests;
  }

  eol::testing::TempDir dir_;
  const std::string db_path_ = dir_ / "variants.sqlite";
  const std::string eight_pole_ = dir_ / "pmsm-8pole-heavy.json";
  const std::string ten_pole_ = dir_ / "pmsm-10pole.json";
  std::unique_ptr<Station> station_;
  std::thread serve_;
};

TEST_F(TwoRecipeStation, AProposalIsRefusedAtStartNamingTheVariantAndTheFile) {
  try {
    Station s(ParseStationConfig(Config(kEightPole), "test", ""));
    FAIL() << "a station started with a proposed recipe";
  } catch (const io::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(what.rfind("variant 'P8H' (" + kEightPole +
                             "): recipe pmsm-8pole-heavy v2 is a "
                             "proposal (eol teach",
                         0),
              0u)
        << what;
    EXPECT_NE(what.find("the station does not start with it"), std::string::npos) << what;
  }
  nlohmann::json twice = Config(eight_pole_);
  twice["variants"][1]["recipe"] = ten_pole_;
  try {
    Station s(ParseStationConfig(twice, "test", ""));
    FAIL() << "two variants of one recipe";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("recipe id 'pmsm-10pole' is already variant 'P10''s"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(db::Store::Open(db_path_, db::Store::Role::kReader)->Tests({}).empty());
}

TEST_F(TwoRecipeStation, EachUnitIsTestedAndRecordedWithItsOwnRecipeOverHttp) {
  Start();
  const Recipe ten = LoadRecipe(kTenPole);
  const Recipe eight = LoadRecipe(eight_pole_);
  ASSERT_NE(ten.hash, eight.hash);

  auto res = Post({{"serial", "P8H-0001"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  res = Post({{"serial", "P10-0001"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  res = Post({{"serial", "ANY-7"}, {"variant", "P8H"}});  // the operator's choice
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  std::vector<db::TestRecord> stored = Stored(3);
  ASSERT_EQ(stored.size(), 3u);

  // Refused: nothing is started and nothing stored, the reason names serial and rules.
  res = Post({{"serial", "X-1"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;
  nlohmann::json error = nlohmann::json::parse(res->body)["error"];
  EXPECT_EQ(error["code"], "no_variant");
  EXPECT_EQ(error["message"],
            "serial 'X-1' matches no variant's part-number prefix or pattern and no variant was "
            "chosen (variants: P10, P8H); choose the variant or check the serial");
  res = Post({{"serial", "P10-0002"}, {"variant", "P8H"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 409) << res->body;
  EXPECT_EQ(nlohmann::json::parse(res->body)["error"]["code"], "variant_conflict");
  res = Post({{"serial", "P10-0003"}, {"variant", "P12"}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;
  EXPECT_EQ(nlohmann::json::parse(res->body)["error"]["code"], "unknown_variant");
  res = Post({{"serial", "P10-0004"}, {"variant", 2}});
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400) << res->body;

  // One accepted start behind the refused ones: tests run one at a time in the order they
  // were accepted, so a refused start that slipped through is stored before this one is.
  res = Post({{"serial", "ANY-8"}, {"variant", "P8H"}});
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 202) << res->body;
  stored = Stored(4);
  ASSERT_EQ(stored.size(), 4u) << "a refused start stored a record";
  std::set<std::string> serials;
  for (const db::TestRecord& r : stored) serials.insert(r.serial);
  EXPECT_EQ(serials, (std::set<std::string>{"P8H-0001", "P10-0001", "ANY-7", "ANY-8"}));
  const auto by_serial = [&](const std::string& serial) {
    for (const db::TestRecord& r : stored)
      if (r.serial == serial) return r;
    ADD_FAILURE() << serial << " not stored";
    return db::TestRecord{};
  };
  const db::TestRecord a = by_serial("P8H-0001");
  EXPECT_EQ(a.recipe_id, "pmsm-8pole-heavy");
  EXPECT_EQ(a.recipe_version, eight.version);
  EXPECT_EQ(a.recipe_hash, eight.hash) << "the approved copy, not the shipped proposal";
  EXPECT_EQ(a.conditions.variant, "P8H");
  EXPECT_EQ(a.conditions.variant_by, "prefix 'P8H-'");
  const db::TestRecord b = by_serial("P10-0001");
  EXPECT_EQ(b.recipe_id, "pmsm-10pole");
  EXPECT_EQ(b.recipe_hash, ten.hash);
  EXPECT_EQ(b.conditions.variant, "P10");
  EXPECT_EQ(b.outcome, analysis::Outcome::kPass) << "the sim's good rotor with its own recipe";
  const db::TestRecord c = by_serial("ANY-7");
  EXPECT_EQ(c.recipe_hash, eight.hash);
  EXPECT_EQ(c.conditions.variant_by, "operator");

  // The API: the verdict names the recipe and variant; the variants with their recipes. The
  // verdict is published just after it is stored: the status shows ANY-8 a moment later.
  httplib::Client http("127.0.0.1", station_->http_port());
  nlohmann::json last;
  ASSERT_TRUE(eol::testing::WaitUntil(
      [&] {
        const auto status = http.Get("/api/status");
        if (status) last = nlohmann::json::parse(status->body)["last"];
        return last.is_object() && last.value("serial", "") == "ANY-8";
      },
      eol::testing::kGenerousDeadline, 50ms))
      << last.dump();
  EXPECT_EQ(last["recipe"]["hash"], eight.hash);
  EXPECT_EQ(last["recipe"]["variant"], "P8H");
  res = http.Get("/api/variants");
  ASSERT_TRUE(res);
  const nlohmann::json v = nlohmann::json::parse(res->body);
  EXPECT_EQ(v["current"], "P8H");
  ASSERT_EQ(v["variants"].size(), 2u);
  EXPECT_EQ(v["variants"][0]["recipe"]["hash"], ten.hash);
  EXPECT_EQ(v["variants"][1]["recipe"]["hash"], eight.hash);
  EXPECT_EQ(v["variants"][1]["plc_code"], 2);
}

TEST_F(TwoRecipeStation, ThePlcsVariantRegisterPicksTheRecipeAndAnUnknownOneStartsNothing) {
  ASSERT_TRUE(peers::PymodbusAvailable());
  Start();
  const plc::PlcMap map;  // the addresses the station serves (station/daemon/plc/plc_map.h)
  // One start: serial and variant register written, start set, then the refusal read, and
  // for an accepted start the wait for done.
  const auto start = [&](const std::string& serial, int code, bool accepted) {
    nlohmann::json ops = {{"write_text", map.serial, plc::kSerialRegisters, serial},
                          {"write_hrs", map.variant, {code}},
                          {"write_coil", map.start, 1},
                          {"wait_coil", map.start, 0, 5},
                          {"read_ir", map.refusal, 1}};
    if (accepted) ops.push_back({"wait_di", map.done, 1, 120});
    std::string log;
    const nlohmann::json out = peers::RunPymodbusClientScript(
        "pymodbus_plc_client.py", {"--tcp", "127.0.0.1:" + std::to_string(station_->plc_port())},
        ops, &log, 300s);
    EXPECT_TRUE(out.is_array() && out.size() == ops.size()) << out.dump() << "\n" << log;
    if (!out.is_array() || out.size() < 5) return -1;
    for (const auto& r : out) EXPECT_FALSE(r.contains("error")) << r.dump() << "\n" << log;
    return out[4]["values"][0].get<int>();
  };
  EXPECT_EQ(start("Q-1", 2, true), 0) << "code 2: P8H, although no prefix names it";
  EXPECT_EQ(start("P10-1", 0, true), 0) << "code 0: the serial's prefix picks P10";
  EXPECT_EQ(start("Q-2", 9, false), static_cast<int>(plc::PlcRefusal::kUnknownVariant));
  EXPECT_EQ(start("Q-3", 0, false), static_cast<int>(plc::PlcRefusal::kNoVariant));
  EXPECT_EQ(start("P8H-1", 1, false), static_cast<int>(plc::PlcRefusal::kVariantConflict));

  const std::vector<db::TestRecord> stored =
      db::Store::Open(db_path_, db::Store::Role::kReader)->Tests(db::TestQuery{});
  ASSERT_EQ(stored.size(), 2u) << "a refused start stored a record";
  EXPECT_EQ(stored[1].serial, "Q-1");
  EXPECT_EQ(stored[1].recipe_id, "pmsm-8pole-heavy");
  EXPECT_EQ(stored[1].recipe_hash, LoadRecipe(eight_pole_).hash);
  EXPECT_EQ(stored[1].conditions.variant_by, "plc code 2");
  EXPECT_EQ(stored[0].serial, "P10-1");
  EXPECT_EQ(stored[0].recipe_id, "pmsm-10pole");
  EXPECT_EQ(stored[0].conditions.variant_by, "prefix 'P10-'");
}

// A station of one recipe (the config of before): unchanged, and it refuses a request naming
// another variant or a PLC code rather than testing with its one recipe.
TEST(OneRecipeStation, RefusesAnotherVariantAndKeepsItsRecipe) {
  eol::testing::TempDir dir;
  const std::string db_path = dir / "one.sqlite";
  const nlohmann::json j = {{"station_id", "one"},
                            {"recipe", kTenPole},
                            {"db", db_path},
                            {"fixture", {{"driver", "sim"}}},
                            {"daq", {{"driver", "sim"}}},
                            {"sim", {{"clamp_close_s", 0.02}, {"clamp_open_s", 0.02}}}};
  Station station(ParseStationConfig(j, "test", ""));
  std::string why;
  VariantRefusal refusal = VariantRefusal::kNone;
  TestRequest request{"SN-1", {}, {"P8H", 0}};
  EXPECT_FALSE(station.Enqueue(request, &why, nullptr, &refusal));
  EXPECT_EQ(refusal, VariantRefusal::kUnknown);
  EXPECT_EQ(why,
            "unknown variant 'P8H': this station runs one recipe (pmsm-10pole) and no variants");
  request.variant = {"", 3};
  EXPECT_FALSE(station.Enqueue(request, &why, nullptr, &refusal));
  EXPECT_EQ(refusal, VariantRefusal::kUnknown);
  const db::TestRecord r = station.RunTest("SN-1");
  EXPECT_EQ(r.recipe_id, "pmsm-10pole");
  EXPECT_FALSE(r.conditions.variant || r.conditions.variant_by)
      << "no variant keys on a one-recipe station";
  EXPECT_EQ(station.VariantsJson()["variants"], nlohmann::json::array());
}

}  // namespace
}  // namespace eol::station

namespace eol::station {
namespace {

// PUT /api/recipe on a station of variants: the new recipe's id picks the variant it replaces;
// the next unit of that variant is tested with it, the other variant keeps its own.
TEST_F(TwoRecipeStation, ANewVersionReplacesTheRecipeOfItsVariantOnly) {
  Start();
  const ApiToken engineer{"qe-test", Role::kEngineer, "engineer-token-0123456789"};
  nlohmann::json next = io::ReadJsonFile(ten_pole_);
  next["version"] = 2;
  const RecipeChange changed = station_->ChangeRecipe(next, engineer);
  ASSERT_EQ(changed.kind, RecipeChange::Kind::kChanged) << changed.message;
  EXPECT_EQ(changed.path, ten_pole_);
  EXPECT_EQ(changed.kept_as, dir_ / "pmsm-10pole.v1.json");
  nlohmann::json other =
      io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole-fast.json");
  const RecipeChange refused = station_->ChangeRecipe(other, engineer);
  EXPECT_EQ(refused.kind, RecipeChange::Kind::kWrongRecipe);
  EXPECT_EQ(refused.message,
            "recipe id 'pmsm-10pole-fast' is none of this station's variants' (P10: "
            "pmsm-10pole, P8H: pmsm-8pole-heavy); a new variant needs a new station config");

  ASSERT_EQ(Post({{"serial", "P10-1"}})->status, 202);
  ASSERT_EQ(Post({{"serial", "P8H-1"}})->status, 202);
  const std::vector<db::TestRecord> stored = Stored(2);
  ASSERT_EQ(stored.size(), 2u);
  EXPECT_EQ(stored[1].serial, "P10-1");
  EXPECT_EQ(stored[1].recipe_version, 2);
  EXPECT_EQ(stored[1].recipe_hash, changed.hash);
  EXPECT_EQ(stored[0].recipe_hash, LoadRecipe(eight_pole_).hash);
  const nlohmann::json v = station_->VariantsJson();
  EXPECT_EQ(v["variants"][0]["recipe"]["version"], 2);
}

}  // namespace
}  // namespace eol::station
