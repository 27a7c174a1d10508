// The recipe's "excitation_design" requirement (station/daemon/recipe.h) and `eol
// design-excitation`: a recipe whose excitation misses the precision it states is refused, naming
// the field; the command writes the shortest excitation that meets it as a proposal that loads.
#include <gtest/gtest.h>

#include <complex>
#include <fstream>
#include <nlohmann/json.hpp>

#include "drivers/io/json_config.h"
#include "station/daemon/recipe.h"
#include "tests/support/child_process.h"
#include "tests/support/recipe_error.h"

namespace eol::station {
namespace {

using testing::ChildProcess;
using testing::TempDir;

const std::string kFast = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole-fast.json";

std::string ErrorOf(const nlohmann::json& j) { return testing::RecipeErrorOf(j); }

TEST(ExcitationDesignRecipe, FastRecipeStatesItsRequirementAndMeetsIt) {
  const Recipe r = LoadRecipe(kFast);
  ASSERT_TRUE(r.excitation_design.has_value());
  const double predicted = analysis::PredictedSigmaF0Hz(
      r.excitation, r.periods + r.transient_periods, *r.excitation_design);
  EXPECT_LE(predicted, r.excitation_design->RequiredSigmaF0Hz() * (1 + 1e-6));
  EXPECT_LE(static_cast<double>(r.periods + r.transient_periods) / r.excitation.line_spacing_hz,
            0.5);
  const nlohmann::json written = RecipeToJson(r);
  EXPECT_EQ(RecipeToJson(ParseRecipe(written, "written")), written);
}

TEST(ExcitationDesignRecipe, ExcitationThatMissesItsRequirementIsRefused) {
  nlohmann::json j = io::ReadJsonFile(kFast);
  j["excitation"]["peak_v"] = j["excitation"]["peak_v"].get<double>() / 2;
  const std::string e = ErrorOf(j);
  EXPECT_NE(e.find("/excitation_design/sigma_f0_hz: the excitation reaches std(f0)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("eol design-excitation"), std::string::npos) << e;
  j = io::ReadJsonFile(kFast);
  j["excitation_design"]["nominal"].erase("q");
  EXPECT_NE(ErrorOf(j).find("/excitation_design/nominal/q: missing"), std::string::npos)
      << ErrorOf(j);
  j = io::ReadJsonFile(kFast);
  j["excitation_design"]["max_peak_v"] = 1.0;  // below the excitation's own peak
  EXPECT_NE(ErrorOf(j).find("/excitation_design/max_peak_v"), std::string::npos) << ErrorOf(j);
}

TEST(ExcitationDesignRecipe, CrestForCurrentDesignsThroughTheNominalMotorAndRoundTrips) {
  nlohmann::json j = io::ReadJsonFile(kFast);
  j["excitation"]["crest_for"] = "current";
  const Recipe r = ParseRecipe(j, "current", {.check_excitation_design = false});
  EXPECT_TRUE(r.crest_for_current);
  ASSERT_TRUE(static_cast<bool>(r.excitation.crest_load_ohm));
  const std::complex<double> z = r.excitation.crest_load_ohm(390.0);
  EXPECT_NEAR(std::abs(z - r.excitation_design->nominal.At(390.0)), 0.0, 1e-12);
  const nlohmann::json written = RecipeToJson(r);
  EXPECT_EQ(written["excitation"]["crest_for"], "current");
  EXPECT_EQ(RecipeToJson(ParseRecipe(written, "written", {.check_excitation_design = false})),
            written);
  EXPECT_FALSE(RecipeToJson(LoadRecipe(std::string(EOL_SOURCE_DIR) +
                                       "/recipes/pmsm-10pole.json"))["excitation"]
                   .contains("crest_for"));

  nlohmann::json bad = j;
  bad.erase("excitation_design");
  EXPECT_NE(ErrorOf(bad).find("/excitation: crest_for \"current\" needs the "
                              "\"excitation_design\" block"),
            std::string::npos)
      << ErrorOf(bad);
  bad = j;
  bad["excitation"]["crest_for"] = "both";
  EXPECT_NE(ErrorOf(bad).find("/excitation/crest_for: must be \"voltage\" or \"current\""),
            std::string::npos)
      << ErrorOf(bad);
}

TEST(ExcitationDesignCli, WritesTheShortestExcitationAsAProposal) {
  TempDir dir;
  // The usual case: a recipe whose excitation does not (yet) meet what it states. It does not
  // load, but the designer reads it.
  nlohmann::json weak = io::ReadJsonFile(kFast);
  weak["excitation"]["peak_v"] = weak["excitation"]["peak_v"].get<double>() / 2;
  ASSERT_NE(ErrorOf(weak), "");
  const std::string input = dir / "weak.json";
  std::ofstream(input) << weak.dump(2);
  const std::string out = dir / "designed.json";
  ChildProcess p({EOL_BINARY, "design-excitation", "--recipe", input, "--sigma-f0-hz", "0.004",
                  "--out", out, "--json"},
                 /*merge_stderr=*/false);
  ASSERT_EQ(p.Wait(std::chrono::seconds(60)), 0) << p.output();
  const nlohmann::json j = nlohmann::json::parse(p.output());
  ASSERT_TRUE(j["usable"].get<bool>()) << j.dump(2);
  const nlohmann::json& c = j["chosen"];
  EXPECT_LE(c["sigma_f0_hz"].get<double>(), 0.004 * (1 + 1e-6));
  for (const auto& other : j["candidates"]) {
    if (other["meets"].get<bool>()) {
      EXPECT_GE(other["record_s"].get<double>(), c["record_s"].get<double>() - 1e-9);
    }
  }

  const Recipe fast = LoadRecipe(kFast);
  const Recipe designed = LoadRecipe(out);  // loads: its bound was checked on load
  EXPECT_EQ(designed.version, fast.version + 1);
  ASSERT_TRUE(designed.approval.has_value());
  EXPECT_EQ(designed.approval->state, "proposed");
  EXPECT_FALSE(designed.Approved());
  EXPECT_DOUBLE_EQ(designed.excitation.peak_v, c["peak_v"].get<double>());
  EXPECT_DOUBLE_EQ(designed.excitation.line_spacing_hz, c["line_spacing_hz"].get<double>());
  EXPECT_EQ(designed.periods, c["periods"].get<std::size_t>());
  EXPECT_EQ(designed.analysis.frf_method, analysis::FrfMethod::kTransientLpm);
  ASSERT_TRUE(designed.excitation_design.has_value());
  EXPECT_DOUBLE_EQ(designed.excitation_design->sigma_f0_hz, 0.004);
  // Twice the precision costs four times the information: more periods or more amplitude.
  EXPECT_GT(static_cast<double>(designed.periods) * designed.excitation.peak_v *
                designed.excitation.peak_v,
            3.0 * static_cast<double>(fast.periods) * fast.excitation.peak_v *
                fast.excitation.peak_v * designed.excitation.line_spacing_hz /
                fast.excitation.line_spacing_hz);

  // Never overwrites without --force.
  ChildProcess again({EOL_BINARY, "design-excitation", "--recipe", kFast, "--out", out});
  EXPECT_EQ(again.Wait(std::chrono::seconds(60)), 2);
  EXPECT_NE(again.output().find("refusing to overwrite"), std::string::npos) << again.output();
}

TEST(ExcitationDesignCli, CrestForCurrentKeepsTheRmsWindowsAroundWhatItDrives) {
  TempDir dir;
  const std::string out = dir / "current.json";
  ChildProcess p({EOL_BINARY, "design-excitation", "--recipe", kFast, "--crest-for", "current",
                  "--sigma-f0-hz", "0.0085", "--out", out, "--json"},
                 /*merge_stderr=*/false);
  ASSERT_EQ(p.Wait(std::chrono::seconds(60)), 0) << p.output();
  const Recipe fast = LoadRecipe(kFast);
  const Recipe designed = LoadRecipe(out);
  EXPECT_TRUE(designed.crest_for_current);
  ASSERT_TRUE(designed.conditions.excitation_v_rms.lo && designed.conditions.excitation_v_rms.hi);
  const analysis::MotionalImpedance& nominal = designed.excitation_design->nominal;
  const analysis::ExcitationDrive was = analysis::DriveThrough(fast.excitation, nominal);
  const analysis::ExcitationDrive now = analysis::DriveThrough(designed.excitation, nominal);
  // Each window is the old one times the rms ratio, so it sits where it sat around the drive.
  EXPECT_NEAR(*designed.conditions.excitation_v_rms.lo / now.v_rms,
              *fast.conditions.excitation_v_rms.lo / was.v_rms, 1e-6);
  EXPECT_NEAR(*designed.conditions.excitation_v_rms.hi / now.v_rms,
              *fast.conditions.excitation_v_rms.hi / was.v_rms, 1e-6);
  EXPECT_NEAR(*designed.conditions.excitation_a_rms.hi / now.a_rms,
              *fast.conditions.excitation_a_rms.hi / was.a_rms, 1e-6);
  EXPECT_LE(now.a_peak, analysis::kCurrentHeadroom *
                            designed.excitation_design->current_full_scale_a * (1 + 1e-6));
  const nlohmann::json j = nlohmann::json::parse(p.output());
  EXPECT_NEAR(j["recipe_excitation"]["current_peak_a"].get<double>(), was.a_peak, 1e-9);
}

TEST(ExcitationDesignCli, RecipeWithoutRequirementNamesTheBlock) {
  ChildProcess p({EOL_BINARY, "design-excitation", "--recipe",
                  std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"});
  EXPECT_EQ(p.Wait(std::chrono::seconds(60)), 2);
  EXPECT_NE(p.output().find("has no \"excitation_design\" block"), std::string::npos) << p.output();
}

}  // namespace
}  // namespace eol::station
