// Recipes: the shipped recipe loads; every malformed recipe is refused with a message that
// names the JSON path and the rule; the hash ignores formatting but not content.
#include "station/daemon/recipe.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>

#include "../support/child_process.h"
#include "../support/recipe_error.h"
#include "drivers/io/json_config.h"

namespace eol::station {
namespace {

const std::string kRecipe = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";

nlohmann::json Good() { return io::ReadJsonFile(kRecipe); }

std::string ErrorOf(const nlohmann::json& j) { return testing::RecipeErrorOf(j); }

TEST(Recipe, ShippedRecipeLoads) {
  const Recipe r = LoadRecipe(kRecipe);
  EXPECT_EQ(r.id, "pmsm-10pole");
  EXPECT_EQ(r.version, 1);
  EXPECT_EQ(r.hash.size(), 64u);
  EXPECT_FALSE(r.limits.empty());
  EXPECT_DOUBLE_EQ(r.analysis.fit.f0_min_hz, 250.0);
  EXPECT_TRUE(r.analysis.fit.second_mode_test) << "declared: second_mode_chi2_drop";
  nlohmann::json j = Good();
  auto& limits = j["limits"];
  limits.erase(std::remove_if(limits.begin(), limits.end(),
                              [](const auto& l) { return l["name"] == "second_mode_chi2_drop"; }),
               limits.end());
  EXPECT_FALSE(ParseRecipe(j, "test.json").analysis.fit.second_mode_test);
}

TEST(Recipe, ErrorsNameTheJsonPathAndRule) {
  struct Case {
    std::function<void(nlohmann::json&)> edit;
    std::string expected;
  };
  const std::vector<Case> cases = {
      {[](auto& j) { j["excitation"]["f_hi_hz"] = 100; },
       "test.json: /excitation/f_hi_hz: must be greater than /excitation/f_lo_hz (got 100)"},
      {[](auto& j) { j["excitation"].erase("peak_v"); }, "/excitation/peak_v: missing (required)"},
      {[](auto& j) { j["excitation"]["peak_v"] = "two"; },
       "/excitation/peak_v: must be a number (got \"two\")"},
      {[](auto& j) { j["excitation"]["periods"] = 1; },
       "/excitation/periods: must be in [2, 1000]"},
      {[](auto& j) { j["fixture"]["clamp_pressure_bar"]["hi"] = 1.0; },
       "/fixture/clamp_pressure_bar/hi: must be greater than /fixture/clamp_pressure_bar/lo"},
      // Issue 14: physical and resource bounds (a recipe cannot exhaust the station or switch
      // off an interlock).
      {[](auto& j) { j["excitation"]["sample_rate_hz"] = 1e10; },
       "/excitation/sample_rate_hz: must be at most 1000000 Hz"},
      {[](auto& j) { j["excitation"]["crest_iterations"] = 600000; },
       "/excitation/crest_iterations: must be in [0, 2000]"},
      {[](auto& j) {
         j["excitation"]["line_spacing_hz"] = 0.1;
         j["excitation"]["periods"] = 10;
         j["excitation"]["transient_periods"] = 1;
       },
       "/excitation/periods: (periods + transient_periods) / line_spacing_hz is 110.0 s"},
      {[](auto& j) {
         j["excitation"]["sample_rate_hz"] = 900000;
         j["excitation"]["line_spacing_hz"] = 0.25;
       },
       "/excitation/sample_rate_hz: gives more than 2097152 samples per period"},
      {[](auto& j) {
         j["fixture"]["clamp_pressure_bar"] = {{"lo", 0.001}, {"hi", 1e6}};
       },
       "/fixture/clamp_pressure_bar/lo: must be at least 0.5 bar"},
      {[](auto& j) {
         j["fixture"]["clamp_pressure_bar"] = {{"lo", 1.0}, {"hi", 9.0}};
       },
       "/fixture/clamp_pressure_bar/hi: must be at most 2 x /fixture/clamp_pressure_bar/lo"},
      {[](auto& j) { j["limits"][0]["name"] = "resonance_hz"; },
       "/limits/0/name: is not a measurement the analysis produces"},
      {[](auto& j) { j["limits"][1]["lo"] = 500; }, "/limits/1/hi: must be greater than lo"},
      {[](auto& j) { j["limits"] = nlohmann::json::array(); },
       "/limits: must be a non-empty array of limits"},
      {[](auto& j) { j["excitaton"] = nlohmann::json::object(); }, "/excitaton: unknown field"},
      {[](auto& j) { j["motor"]["poles"] = 9; }, "/motor/poles: must be an even number >= 2"},
      {[](auto& j) { j["analysis"]["f0_max_hz"] = 900; },
       "/analysis/f0_max_hz: must lie inside the excited band"},
      {[](auto& j) { j["version"] = 0; }, "/version: must be a whole number >= 1"},
      {[](auto& j) { j["analysis"]["frf_method"] = "lpm"; },
       "/analysis/frf_method: must be \"discard_transient\" or \"transient_lpm\" (got "
       "\"lpm\")"},
      {[](auto& j) {
         j["excitation"]["phase_pairs"] = {0, 1};
       },
       "/excitation/phase_pairs: give phase_pair or phase_pairs, not both"},
      {[](auto& j) {
         j["excitation"].erase("phase_pair");
         j["excitation"]["phase_pairs"] = {0, 3};
       },
       "/excitation/phase_pairs: must be 0 (U-V), 1 (V-W) or 2 (W-U)"},
      {[](auto& j) {
         j["excitation"].erase("phase_pair");
         j["excitation"]["phase_pairs"] = {1, 1};
       },
       "/excitation/phase_pairs: names a phase pair twice"},
      {[](auto& j) {
         j["excitation"].erase("phase_pair");
         j["excitation"]["phase_pairs"] = nlohmann::json::array();
       },
       "/excitation/phase_pairs: must be a list of 1 to 3 phase pairs"},
      // Issue 12: the bond index needs its definition, and a sane one.
      {[](auto& j) { j.erase("bond_index"); },
       "/bond_index: is required when a limit is declared on bond_index_pct"},
      {[](auto& j) { j["bond_index"]["f0_exponent"] = -1; },
       "/bond_index/f0_exponent: must be in [0, 1000]"},
      {[](auto& j) { j["bond_index"]["residue_ref_ohm_per_s"] = 0; },
       "/bond_index/residue_ref_ohm_per_s: must be positive"},
      {[](auto& j) { j["bond_index"]["f0_ref"] = 390; }, "/bond_index/f0_ref: unknown field"},
      // The resonance at the reference clamp pressure needs its definition, and a sane one.
      {[](auto& j) {
         j["limits"].push_back({{"name", "resonance_f_ref_pressure_hz"}, {"lo", 370.0}});
       },
       "/f0_pressure: is required when a limit is declared on resonance_f_ref_pressure_hz"},
      {[](auto& j) {
         j["f0_pressure"] = {{"exponent", 0.7}, {"pressure_ref_bar", 5.5}};
       },
       "/f0_pressure/exponent: must be in (0, 0.5]"},
      {[](auto& j) {
         j["f0_pressure"] = {{"exponent", 0.1}, {"pressure_ref_bar", -1}};
       },
       "/f0_pressure/pressure_ref_bar: pressure_ref_bar must be positive"},
      {[](auto& j) {
         j["f0_pressure"] = {{"exponent", 0.1}};
       },
       "/f0_pressure/pressure_ref_bar"},
      {[](auto& j) { j["bond_index"]["f0"] = "resonance_f_ref_pressure_hz"; },
       "/f0_pressure: is required when bond_index weighs resonance_f_ref_pressure_hz"},
      {[](auto& j) { j["bond_index"]["f0"] = "winding_r_ohm"; },
       "/bond_index/f0: must be resonance_f_hz or resonance_f_ref_pressure_hz"},
  };
  for (const Case& c : cases) {
    nlohmann::json j = Good();
    c.edit(j);
    const std::string err = ErrorOf(j);
    EXPECT_NE(err.find(c.expected), std::string::npos)
        << "got: " << err << "\nwant: " << c.expected;
  }
}

// Issue 16: the analysis block chooses the FRF estimator; absent, the discarding one. The
// shipped recipe discards the first period; its 0.5 s variant removes the transient.
TEST(Recipe, FrfMethodIsChosenInTheAnalysisBlock) {
  EXPECT_EQ(LoadRecipe(kRecipe).analysis.frf_method, analysis::FrfMethod::kDiscardTransient);
  EXPECT_EQ(LoadRecipe(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole-fast.json")
                .analysis.frf_method,
            analysis::FrfMethod::kTransientLpm);
  nlohmann::json j = Good();
  j["analysis"].erase("frf_method");
  EXPECT_EQ(ParseRecipe(j, "test.json").analysis.frf_method,
            analysis::FrfMethod::kDiscardTransient);
  j["analysis"]["frf_method"] = "transient_lpm";
  j["excitation"]["transient_periods"] = 0;
  j["excitation"]["periods"] = 2;
  const Recipe r = ParseRecipe(j, "test.json");
  EXPECT_EQ(r.analysis.frf_method, analysis::FrfMethod::kTransientLpm);
  EXPECT_EQ(RecipeToJson(r)["analysis"]["frf_method"], "transient_lpm");
  j["analysis"]["frf_method"] = "discard_transient";
  EXPECT_EQ(ParseRecipe(j, "test.json").analysis.frf_method,
            analysis::FrfMethod::kDiscardTransient);
}

TEST(Recipe, PhasePairsInOrder) {
  nlohmann::json j = Good();
  j["excitation"].erase("phase_pair");
  j["excitation"]["phase_pairs"] = {2, 0};
  const Recipe r = ParseRecipe(j, "test.json");
  ASSERT_EQ(r.phase_pairs.size(), 2u);
  EXPECT_EQ(r.phase_pairs[0], drivers::PhasePair::kWU);
  EXPECT_EQ(r.phase_pairs[1], drivers::PhasePair::kUV);
  EXPECT_EQ(r.phase_pair, drivers::PhasePair::kWU);
  EXPECT_EQ(LoadRecipe(kRecipe).phase_pairs.size(), 1u);
}

TEST(Recipe, SyntaxErrorNamesTheFile) {
  eol::testing::TempDir dir;
  const std::string path = dir / "broken.json";
  std::ofstream(path) << "{\"id\": \"x\", ";
  try {
    LoadRecipe(path);
    FAIL() << "a broken file was accepted";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(path + ": not valid JSON"), std::string::npos) << e.what();
  }
}

TEST(Recipe, HashIgnoresFormattingButNotContent) {
  const nlohmann::json j = Good();
  const Recipe a = ParseRecipe(j, "a");
  const Recipe b = ParseRecipe(nlohmann::json::parse(j.dump(4)), "b");
  EXPECT_EQ(a.hash, b.hash);
  nlohmann::json changed = j;
  changed["limits"][0]["lo"] = 371;
  EXPECT_NE(ParseRecipe(changed, "c").hash, a.hash);
}

TEST(Recipe, Sha256KnownAnswer) {
  // FIPS 180-2 test vector.
  EXPECT_EQ(Sha256Hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
}

}  // namespace
}  // namespace eol::station

namespace eol::station {
namespace {

TEST(RecipeMasks, ShippedMaskParsesAndBadMasksNameTheirPath) {
  const Recipe r = LoadRecipe(kRecipe);
  ASSERT_EQ(r.masks.size(), 1u);
  EXPECT_EQ(r.Specs().size(), r.limits.size() + 1);
  EXPECT_EQ(r.Specs().back().name, "mask_re_z_low_band_lines_outside");

  nlohmann::json j = Good();
  j["masks"][0]["points"][1]["f_hz"] = 100;
  EXPECT_NE(ErrorOf(j).find("/masks/0/points: point 1: f_hz must increase"), std::string::npos)
      << ErrorOf(j);
  j = Good();
  j["masks"][0]["quantity"] = "phase";
  EXPECT_NE(ErrorOf(j).find("/masks/0/quantity: must be re_ohm or abs_ohm"), std::string::npos);
  j = Good();
  j["masks"][0]["points"][0].erase("hi");
  EXPECT_NE(ErrorOf(j).find("/masks/0/points: point 0: needs lo, hi or both"), std::string::npos);
}

}  // namespace
}  // namespace eol::station

namespace eol::station {
namespace {

// Every key of `part` is in `whole` with the same value (arrays element by element).
void ExpectContained(const nlohmann::json& part, const nlohmann::json& whole,
                     const std::string& path) {
  if (part.is_object()) {
    ASSERT_TRUE(whole.is_object()) << path << ": not an object in " << whole.dump();
    for (const auto& [key, value] : part.items()) {
      ASSERT_TRUE(whole.contains(key)) << path << "/" << key << " is not written";
      ExpectContained(value, whole.at(key), path + "/" + key);
    }
  } else if (part.is_array()) {
    ASSERT_TRUE(whole.is_array() && whole.size() == part.size()) << path;
    for (std::size_t i = 0; i < part.size(); ++i)
      ExpectContained(part[i], whole[i], path + "/" + std::to_string(i));
  } else if (part.is_number()) {
    EXPECT_DOUBLE_EQ(part.get<double>(), whole.get<double>()) << path;
  } else {
    EXPECT_EQ(part, whole) << path;
  }
}

TEST(RecipeJson, OneFieldListReadsAndWritesEveryKey) {
  nlohmann::json source = io::ReadJsonFile(kRecipe);
  source["excitation"].erase("phase_pair");
  source["excitation"]["phase_pairs"] = {0, 2};
  source["retest"] = {{"max_tests_per_serial", 5}};
  source["conditions"] = {
      {"winding_temperature_c", {{"r_ref_ohm", 0.5}, {"t_ref_c", 21.0}, {"lo", 5.0}, {"hi", 45.0}}},
      {"excitation_v_rms", {{"lo", 0.1}}},
      {"excitation_a_rms", {{"hi", 3.0}}},
      {"out_of_window", "record"}};
  source["f0_pressure"] = {{"exponent", 0.114}, {"pressure_ref_bar", 5.5}};
  source["bond_index"]["f0"] = "resonance_f_ref_pressure_hz";
  source["limits"].push_back({{"name", "resonance_f_ref_pressure_hz"},
                              {"unit", "Hz"},
                              {"doc", ""},
                              {"lo", 372.0},
                              {"marginal", 0.0}});
  const Recipe r = ParseRecipe(source, "test");
  const nlohmann::json written = RecipeToJson(r);
  ExpectContained(source, written, "");  // nothing the file said is lost or changed
  const Recipe again = ParseRecipe(written, "written");
  EXPECT_EQ(RecipeToJson(again), written);  // and what is written reads back the same
  EXPECT_EQ(again.phase_pairs, r.phase_pairs);
  EXPECT_EQ(again.masks.size(), r.masks.size());
  EXPECT_FALSE(again.conditions.error_when_out);
  EXPECT_EQ(again.instructions, r.instructions);
  EXPECT_EQ(again.f0_pressure, r.f0_pressure);
  EXPECT_EQ(again.bond_index, r.bond_index);
}

// Issue 17: what the operator does after FAIL, ERROR or ABORTED comes from the recipe; a key
// left out keeps its default, and nothing but short text is accepted.
TEST(RecipeInstructions, ShippedTextDefaultsAndStrictValidation) {
  const Recipe shipped = LoadRecipe(kRecipe);
  EXPECT_EQ(shipped.instructions.fail, "Red bin: put the rotor in the red reject bin");

  nlohmann::json j = Good();
  j.erase("instructions");
  EXPECT_EQ(ParseRecipe(j, "none").instructions, OperatorInstructions{});
  j["instructions"] = {{"error", "Call line 3 maintenance"}};
  const Recipe partial = ParseRecipe(j, "partial");
  EXPECT_EQ(partial.instructions.error, "Call line 3 maintenance");
  EXPECT_EQ(partial.instructions.fail, OperatorInstructions{}.fail);
  EXPECT_EQ(RecipeToJson(partial)["instructions"]["aborted"], OperatorInstructions{}.aborted);

  const std::string rule = "must be 1 to 200 bytes of text without control characters";
  const std::vector<std::pair<nlohmann::json, std::string>> bad = {
      {{{"fail", 3}}, "/instructions/fail: must be a string (got 3)"},
      {{{"error", ""}}, "/instructions/error: " + rule},
      {{{"aborted", std::string(201, 'x')}}, "/instructions/aborted: " + rule},
      {{{"fail", "red\nbin"}}, "/instructions/fail: " + rule},
      {{{"pass", "green bin"}}, "/instructions/pass: unknown field"},
      {"red bin", "/instructions: must be a JSON object"},
  };
  for (const auto& [instructions, expected] : bad) {
    j = Good();
    j["instructions"] = instructions;
    const std::string err = ErrorOf(j);
    EXPECT_NE(err.find(expected), std::string::npos) << "got: " << err << "\nwant: " << expected;
  }
  j = Good();
  j["instructions"] = {{"fail", std::string(200, 'x')}};
  EXPECT_EQ(ErrorOf(j), "");
}

}  // namespace
}  // namespace eol::station

namespace eol::station {
namespace {

const std::string kFast = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole-fast.json";

std::string ErrorOfEdited(const std::string& path,
                          const std::function<void(nlohmann::json&)>& edit) {
  nlohmann::json j = io::ReadJsonFile(path);
  edit(j);
  return ErrorOf(j);
}

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

// Issue 37: the measurement owns its unit. A limit stating another unit (bounds in kHz on a
// measurement in Hz) is refused naming the measurement, the unit given and the unit expected;
// the right unit, or none, loads, and the unit read is the measurement's.
TEST(RecipeUnits, ALimitInAnotherUnitIsRefused) {
  const std::string khz = ErrorOfEdited(kRecipe, [](auto& j) {
    j["limits"][0]["unit"] = "kHz";
    j["limits"][0]["lo"] = 0.37;
    j["limits"][0]["hi"] = 0.42;
  });
  EXPECT_CONTAINS(khz,
                  "/limits/0/unit: is \"kHz\", but resonance_f_hz is measured in \"Hz\": "
                  "give lo and hi in Hz");
  EXPECT_CONTAINS(ErrorOfEdited(kRecipe, [](auto& j) { j["limits"][2]["unit"] = "mohm"; }),
                  "/limits/2/unit: is \"mohm\", but winding_r_ohm is measured in \"ohm\"");
  EXPECT_CONTAINS(ErrorOfEdited(kRecipe, [](auto& j) { j["limits"][1]["unit"] = "%"; }),
                  "resonance_q is measured in \"1\"");
  nlohmann::json j = Good();
  for (auto& l : j["limits"]) l.erase("unit");
  const Recipe r = ParseRecipe(j, "no-units.json");
  for (const analysis::MeasurementSpec& s : r.limits)
    EXPECT_EQ(s.unit, analysis::names::UnitOf(s.name)) << s.name;
  EXPECT_EQ(RecipeToJson(r)["limits"][0]["unit"], "Hz");
  for (const std::string& path : {kRecipe, kFast}) EXPECT_EQ(ErrorOf(io::ReadJsonFile(path)), "");
}

// Issue 37: resonance limits inside the analysis' f0 window (itself inside the excited band),
// and the window moved alone says what else to move.
TEST(RecipePlausibility, ResonanceLimitsAndWindowsLieInsideTheExcitedBand) {
  EXPECT_CONTAINS(ErrorOfEdited(kRecipe, [](auto& j) { j["limits"][0]["hi"] = 750; }),
                  "/limits/0/hi: is 750.000 Hz, outside the analysis f0 window [250.0, 700.0] Hz "
                  "(/analysis/f0_min_hz, f0_max_hz) inside the excited band [200.0, 800.0] Hz: "
                  "the fit reports no resonance there");
  EXPECT_CONTAINS(ErrorOfEdited(kRecipe, [](auto& j) { j["limits"][0]["lo"] = 100; }),
                  "/limits/0/lo: is 100.000 Hz, outside the analysis f0 window");
  const std::string window =
      ErrorOfEdited(kRecipe, [](auto& j) { j["analysis"]["f0_max_hz"] = 900; });
  EXPECT_CONTAINS(window,
                  "/analysis/f0_max_hz: must lie inside the excited band [200.0, 800.0] Hz "
                  "(/excitation/f_lo_hz, f_hi_hz): the fit only sees excited lines; move "
                  "/excitation/f_hi_hz up to 900.0 Hz or above too");
  EXPECT_CONTAINS(window, "run eol design-excitation on the edited recipe");
  EXPECT_CONTAINS(ErrorOfEdited(kRecipe, [](auto& j) { j["analysis"]["f0_min_hz"] = 150; }),
                  "move /excitation/f_lo_hz down to 150.0 Hz or below too");
  // Moving both is accepted.
  EXPECT_EQ(ErrorOfEdited(kRecipe,
                          [](auto& j) {
                            j["analysis"]["f0_max_hz"] = 900;
                            j["excitation"]["f_hi_hz"] = 1000;
                          }),
            "");
}

// Issue 37: a recipe whose limits cannot pass its own nominal motor, or whose winding
// reference reads its nominal winding as an implausible temperature, is refused; the
// precision requirement's refusal says how to choose it for a new motor.
TEST(RecipePlausibility, TheNominalMotorMustPassItsOwnRecipe) {
  const std::string foreign = ErrorOfEdited(kFast, [](auto& j) {
    j["excitation_design"]["nominal"]["f0_hz"] = 600;
    j["excitation_design"]["nominal"]["r_ohm"] = 1.1;
  });
  EXPECT_CONTAINS(foreign,
                  "/excitation_design/nominal: the recipe's own nominal motor (the good motor it "
                  "expects) fails its limits: resonance_f_hz = 600");
  EXPECT_CONTAINS(foreign, "winding_r_ohm = 1.1");
  EXPECT_CONTAINS(foreign, "teach the limits from this motor's golden units");
  const std::string r_ref = ErrorOfEdited(
      kFast, [](auto& j) { j["conditions"]["winding_temperature_c"]["r_ref_ohm"] = 0.1; });
  EXPECT_CONTAINS(r_ref,
                  "/excitation_design/nominal: the nominal winding r_ohm 0.5000 ohm reads "
                  "as a winding temperature of 1037.8 degC");
  EXPECT_CONTAINS(r_ref, "r_ref_ohm is another motor's");
  const std::string sigma =
      ErrorOfEdited(kFast, [](auto& j) { j["excitation_design"]["sigma_f0_hz"] = 0.001; });
  EXPECT_CONTAINS(sigma, "/excitation_design/sigma_f0_hz: the excitation reaches std(f0) ");
  EXPECT_CONTAINS(sigma,
                  "sigma_f0_hz is the std(f0) one test must reach at the nominal motor, "
                  "chosen per motor");
  EXPECT_CONTAINS(sigma, "1/10 of the good units' std(f0)");
  EXPECT_CONTAINS(sigma,
                  "the resonance limits [370.0, 420.0] Hz taken as +-3 std of good units "
                  "give 1/10 of it = 0.8333 Hz");
  EXPECT_CONTAINS(sigma, "eol design-excitation designs the shortest excitation");
}

}  // namespace
}  // namespace eol::station

namespace eol::station {
namespace {

// Issue 37: the bond index's defect direction is the recipe's (its motor's), 12 by default
// (the ten-pole motor's), validated and written back when it differs.
TEST(RecipeBondIndex, DefectDirectionIsARecipeParameter) {
  EXPECT_EQ(LoadRecipe(kRecipe).bond_index->residue_to_f0, analysis::kResidueToF0);
  nlohmann::json j = Good();
  j["bond_index"]["residue_to_f0"] = 3.8;
  const Recipe r = ParseRecipe(j, "other-motor.json");
  EXPECT_EQ(r.bond_index->residue_to_f0, 3.8);
  EXPECT_EQ(RecipeToJson(r)["bond_index"]["residue_to_f0"], 3.8);
  EXPECT_FALSE(RecipeToJson(LoadRecipe(kRecipe))["bond_index"].contains("residue_to_f0"));
  j["bond_index"]["residue_to_f0"] = 0;
  EXPECT_NE(ErrorOf(j).find("/bond_index/residue_to_f0: must be in (0, 1000]: d ln(residue) / "
                            "-d ln(f0) of this motor's softer bonds"),
            std::string::npos)
      << ErrorOf(j);
}

}  // namespace
}  // namespace eol::station
