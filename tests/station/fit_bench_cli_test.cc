// `eol fit-bench` through the binary with a tiny number of runs: it works and reports every
// figure (not timed, no thresholds on speed or on the statistics of so few runs). The SciPy
// pipeline is a declared test dependency: it must have run.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>

#include "tests/support/child_process.h"

namespace eol {
namespace {

TEST(FitBenchCliTest, TinyRunReportsEveryFigure) {
  testing::ChildProcess p(
      {EOL_BINARY, "fit-bench", "--runs", "4", "--check-runs", "3", "--peer-runs", "2", "--json",
       "--recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
      /*merge_stderr=*/false);
  const auto code = p.Wait(std::chrono::seconds(300));
  ASSERT_TRUE(code.has_value()) << "fit-bench did not finish";
  ASSERT_EQ(*code, 0) << p.output();
  const nlohmann::json j = nlohmann::json::parse(p.output(), nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << p.output();
  EXPECT_EQ(j["usable_runs"], 4);
  EXPECT_GT(j["f0"]["std_hz"].get<double>(), 0.0);
  EXPECT_GT(j["f0"]["crb_hz"].get<double>(), 0.0);
  EXPECT_GT(j["f0"]["std_over_crb"].get<double>(), 0.0);
  EXPECT_GE(j["coverage_2sigma"].get<double>(), 0.0);
  EXPECT_LT(j["bias"]["peak_pick_hz"].get<double>(), -1.0);  // |Z| peaks below f0
  EXPECT_GT(j["time"]["analysis_ms_mean"].get<double>(), 0.0);
  EXPECT_TRUE(j["time"]["scipy_ran"].get<bool>())
      << "the SciPy pipeline did not run (python3-scipy is a declared dependency): "
      << j["time"]["scipy_message"];
  EXPECT_LT(j["time"]["scipy_max_f0_diff_over_crb"].get<double>(), 0.01);
  EXPECT_GT(j["measurement_time"]["needed_s"].get<double>(), 0.0);
  EXPECT_GT(j["measurement_time"]["check_measured_f0_std_hz"].get<double>(), 0.0);
}

}  // namespace
}  // namespace eol
