// The operator page's words (issue 36): every catalogue in station/web/i18n/ has every key of
// the English one, and English has operator words for everything the C++ can put in front of
// an operator: every reason code and cause (station/daemon/reason_cause.h), every not-ready cause
// (station/daemon/health.h), every measurement the analysis names, every step of the sequence. The
// lists are enumerated here from the C++, so a code added without its words fails this test.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "analysis/qc/measurement.h"
#include "analysis/qc/measurement_json.h"
#include "analysis/qc/measurement_names.h"
#include "drivers/io/json_config.h"
#include "station/daemon/config.h"
#include "station/daemon/health.h"
#include "station/daemon/reason_cause.h"
#include "station/daemon/recipe.h"
#include "station/daemon/sequencer.h"

namespace eol::station {
namespace {

const std::filesystem::path kWeb = std::filesystem::path(EOL_SOURCE_DIR) / "station/web";

nlohmann::json Catalogue(std::string_view language) {
  std::ifstream in(kWeb / "i18n" / (std::string(language) + ".json"));
  EXPECT_TRUE(in.good()) << "no catalogue station/web/i18n/" << language << ".json";
  if (!in) return nlohmann::json::object();
  return nlohmann::json::parse(in);
}

// The {placeholders} a text fills in: a translation must keep every one.
std::set<std::string> Placeholders(const std::string& text) {
  std::set<std::string> names;
  static const std::regex kName(R"(\{([a-z0-9_]+)\})");
  for (std::sregex_iterator it(text.begin(), text.end(), kName), end; it != end; ++it)
    names.insert((*it)[1]);
  return names;
}

// Every key the C++ can make the page show, as the catalogue names it.
std::vector<std::string> KeysTheStationEmits() {
  std::vector<std::string> keys;
  for (analysis::ReasonCode c : analysis::kAllReasonCodes)
    for (const char* kind : {"what.", "do."}) keys.push_back(kind + std::string(ToString(c)));
  for (std::string_view c : cause::kAllCauses)
    for (const char* kind : {"what.", "do."}) keys.push_back(kind + std::string(c));
  for (NotReadyCause c : kNotReadyCauses) keys.push_back("not_ready." + std::string(Code(c)));
  for (std::string_view m : analysis::names::kAll) keys.push_back("measurement." + std::string(m));
  for (int s = 0; s <= static_cast<int>(SeqState::kConfirmRelease); ++s)
    keys.push_back("state." + std::string(ToString(static_cast<SeqState>(s))));
  return keys;
}

TEST(OperatorWords, EnglishHasWordsForEveryCodeCauseStateAndMeasurement) {
  const nlohmann::json en = Catalogue("en");
  for (const std::string& key : KeysTheStationEmits()) {
    ASSERT_TRUE(en.contains(key)) << "station/web/i18n/en.json has no \"" << key << "\"";
    EXPECT_TRUE(en[key].is_string() && !en[key].get<std::string>().empty()) << key;
  }
}

TEST(OperatorWords, EveryCatalogueHasEveryEnglishKeyWithItsPlaceholders) {
  const nlohmann::json en = Catalogue("en");
  ASSERT_GT(en.size(), 50u);
  for (std::string_view language : kPageLanguages) {
    const nlohmann::json other = Catalogue(language);
    for (const auto& [key, text] : en.items()) {
      ASSERT_TRUE(other.contains(key)) << language << ".json misses \"" << key << "\"";
      ASSERT_TRUE(other[key].is_string()) << language << ".json: \"" << key << "\"";
      const std::string shown = other[key].get<std::string>();
      EXPECT_FALSE(shown.empty()) << language << ".json: \"" << key << "\" is empty";
      EXPECT_EQ(Placeholders(shown), Placeholders(text.get<std::string>()))
          << language << ".json: \"" << key << "\" changes the placeholders";
    }
    for (const auto& [key, text] : other.items())
      EXPECT_TRUE(en.contains(key))
          << language << ".json has \"" << key << "\", which English does not (a stale key?)";
  }
}

// The catalogues on disk are exactly the station's languages: a file without its entry in
// kPageLanguages could not be chosen, an entry without its file would show raw keys.
TEST(OperatorWords, TheCataloguesAreTheStationsLanguages) {
  std::set<std::string> files;
  for (const auto& e : std::filesystem::directory_iterator(kWeb / "i18n"))
    if (e.path().extension() == ".json") files.insert(e.path().stem());
  const std::set<std::string> languages(kPageLanguages.begin(), kPageLanguages.end());
  EXPECT_EQ(files, languages);
}

TEST(OperatorWords, EveryCauseSitsUnderItsReasonCode) {
  std::set<std::string_view> seen;
  for (std::string_view c : cause::kAllCauses) {
    EXPECT_TRUE(seen.insert(c).second) << c << " twice";
    const auto dot = c.find('.');
    ASSERT_NE(dot, std::string_view::npos) << c;
    EXPECT_TRUE(analysis::ParseReasonCode(std::string(c.substr(0, dot))).has_value()) << c;
  }
  EXPECT_EQ(analysis::kAllReasonCodes.size(),
            static_cast<std::size_t>(analysis::ReasonCode::kClipped) + 1)
      << "a ReasonCode is missing from kAllReasonCodes";
}

// The page shows the recipe's instruction only where the recipe changed it: it knows the
// defaults (station/web/app.js RECIPE_DEFAULTS), which must be recipe.h's.
TEST(OperatorWords, ThePageKnowsTheRecipesDefaultInstructions) {
  std::ifstream in(kWeb / "app.js");
  std::stringstream app;
  app << in.rdbuf();
  const OperatorInstructions d;
  for (const std::string& text : {d.fail, d.error, d.aborted})
    EXPECT_NE(app.str().find('"' + text + '"'), std::string::npos) << text;
}

TEST(OperatorWords, TheCauseTravelsWithTheReasonAndOldRecordsHaveNone) {
  const analysis::Reason door{analysis::ReasonCode::kInterlock, "interlock: door open",
                              std::string(cause::kDoorOpen)};
  const nlohmann::json j = door;
  EXPECT_EQ(j.at("cause"), "interlock.door_open");
  EXPECT_EQ(j.get<analysis::Reason>(), door);
  // Stored before causes: no "cause" key, and none is guessed from the text.
  const auto old = nlohmann::json::parse(R"({"code": "interlock", "text": "interlock: door open"})")
                       .get<analysis::Reason>();
  EXPECT_EQ(old.code, analysis::ReasonCode::kInterlock);
  EXPECT_TRUE(old.cause.empty());
  EXPECT_FALSE(nlohmann::json(old).contains("cause")) << "no cause is written where none is";
  EXPECT_EQ(nlohmann::json("door open").get<analysis::Reason>().code,
            analysis::ReasonCode::kLegacy);
}

TEST(OperatorWords, TheStationsLanguageIsCheckedNamingThePath) {
  const nlohmann::json base = {{"recipe", "r.json"},
                               {"db", "s.sqlite"},
                               {"fixture", {{"driver", "sim"}}},
                               {"daq", {{"driver", "sim"}}}};
  EXPECT_EQ(ParseStationConfig(base, "test", "").language, "en");
  nlohmann::json de = base;
  de["language"] = "de";
  EXPECT_EQ(ParseStationConfig(de, "test", "").language, "de");
  nlohmann::json bad = base;
  bad["language"] = "fr";
  try {
    ParseStationConfig(bad, "station.json", "");
    ADD_FAILURE() << "language fr accepted";
  } catch (const io::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("language"), std::string::npos) << what;
    EXPECT_NE(what.find("en, de, ja"), std::string::npos) << what;
    EXPECT_NE(what.find("fr"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace eol::station
