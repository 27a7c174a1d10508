// Independent check of the transient-aware estimator (analysis/signal/transient_frf.h) on data
// from a model it shares no code with: tests/peers/transient_scipy_peer.py integrates the
// clamped motor's equations from rest with scipy's solve_ivp on the continuous multisine
// (0.5 s: 2 periods at 4 Hz spacing, 200-800 Hz, 8 kHz, noise 2 mV / 1 mA rms per sample)
// and writes 20 recording CSVs with independent noise. Each goes through `eol analyze
// --recipe` with the shipped recipe switched to that excitation and "frf_method":
// "transient_lpm", the station's path. f0 must lie within 4 reported sigmas of the truth on
// every record, and the reported sigma must be honest: the rms of (f0 - truth) / sigma over
// the 20 records within [0.6, 1.45] (the 95 % range of a chi with 20 dof is [0.69, 1.31]).
// python3-scipy is a declared dependency: if it is missing the test fails, it does not skip.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "drivers/io/json_config.h"
#include "tests/support/child_process.h"

namespace eol {
namespace {

constexpr const char* kPython = "/usr/bin/python3";
constexpr int kRecords = 20;

TEST(TransientScipyPeerTest, F0FromRestRecordingsIsWithinItsSigma) {
  ASSERT_EQ(access(kPython, X_OK), 0)
      << kPython << " not found: python3 with python3-scipy is a declared dependency";
  const std::string script = std::string(EOL_SOURCE_DIR) + "/tests/peers/transient_scipy_peer.py";
  testing::TempDir dir;
  testing::ChildProcess peer({kPython, script, dir.path(), std::to_string(kRecords), "16"},
                             /*merge_stderr=*/false);
  const auto code = peer.Wait(std::chrono::seconds(300));
  ASSERT_TRUE(code.has_value()) << "scipy peer did not finish in 300 s";
  ASSERT_NE(*code, 2) << "python3-scipy is a declared dependency and is missing: " << peer.output();
  ASSERT_EQ(*code, 0) << peer.output();
  const nlohmann::json truth = nlohmann::json::parse(peer.output(), nullptr, false);
  ASSERT_FALSE(truth.is_discarded()) << peer.output();
  // The records do hold a start transient (first period against the second).
  EXPECT_GT(truth["transient_rms_a"].get<double>(), 0.02 * truth["current_rms_a"].get<double>());

  nlohmann::json recipe =
      io::ReadJsonFile(std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json");
  recipe["excitation"]["line_spacing_hz"] = 4.0;
  recipe["excitation"]["periods"] = 2;
  recipe["excitation"]["transient_periods"] = 0;
  recipe["analysis"]["frf_method"] = "transient_lpm";
  recipe.erase("conditions");  // judged elsewhere; here only f0 counts
  recipe.erase("masks");
  const std::string recipe_path = dir / "fast.json";
  std::ofstream(recipe_path) << recipe.dump(2);

  const double f0_true = truth["f0_hz"].get<double>();
  double sum_z2 = 0.0;
  for (int r = 0; r < kRecords; ++r) {
    const std::string csv = dir / ("rec_" + std::to_string(r) + ".csv");
    testing::ChildProcess analyze(
        {EOL_BINARY, "analyze", "--measured", csv, "--recipe", recipe_path, "--json"},
        /*merge_stderr=*/false);
    const auto done = analyze.Wait(std::chrono::seconds(60));
    ASSERT_TRUE(done.has_value()) << "eol analyze did not finish";
    const nlohmann::json j = nlohmann::json::parse(analyze.output(), nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << analyze.output();
    ASSERT_TRUE(j.value("usable", false)) << analyze.output();
    ASSERT_EQ(j["frf"]["method"], "transient-lpm") << analyze.output();
    ASSERT_EQ(j["frf"]["periods_used"], 2);
    const double f0 = j["resonance"]["f_hz"].get<double>();
    const double sigma = j["resonance"]["f_sigma_hz"].get<double>();
    const double z = (f0 - f0_true) / sigma;
    EXPECT_LT(std::abs(z), 4.0) << "record " << r << ": f0 " << f0 << " +- " << sigma;
    sum_z2 += z * z;
  }
  const double rms_z = std::sqrt(sum_z2 / kRecords);
  std::printf("scipy %s peer, %d records from rest: rms (f0 - truth) / sigma = %.3f\n",
              truth.value("scipy_version", "?").c_str(), kRecords, rms_z);
  EXPECT_GT(rms_z, 0.6);
  EXPECT_LT(rms_z, 1.45);
}

}  // namespace
}  // namespace eol
