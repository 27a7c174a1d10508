// `eol safety-bench`'s measurement (station/bench/safety_bench.h) over both fixtures: every
// injected fault must end its test ERROR and yield a measured reaction (relay open after the fault
// was visible). The figures themselves are benchmark output (station/README.md), not asserted here.
#include "station/bench/safety_bench.h"

#include <gtest/gtest.h>

#include <string>

namespace eol::station {
namespace {

class SafetyBenchFixture : public ::testing::TestWithParam<std::string> {};

TEST_P(SafetyBenchFixture, EveryFaultEndsInErrorWithAReactionMeasured) {
  SafetyBenchOptions o;
  o.trials_per_fault = 2;
  o.seed = 3;
  o.fixture = GetParam();
  o.recipe_path = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";
  const auto stats = RunSafetyBench(o);
  ASSERT_EQ(stats.size(), 5u);
  // The controller's side: the relay opened by itself after the station stopped, no
  // earlier than its alive timeout (250 ms) and not much later.
  const ReactionStats& stops = stats.back();
  EXPECT_EQ(stops.fault, "station_stops");
  EXPECT_EQ(stops.errors, 2) << "the relay stayed closed after the station stopped";
  EXPECT_EQ(stops.measured, 2);
  EXPECT_GE(stops.min_ms, 240.0);
  EXPECT_LE(stops.max_ms, 400.0);
  for (const auto& s : stats) {
    EXPECT_EQ(s.trials, 2) << s.fault;
    EXPECT_EQ(s.errors, 2) << s.fault << ": a fault during excitation must end ERROR";
    EXPECT_EQ(s.measured, 2) << s.fault << ": no reaction measured";
    EXPECT_GE(s.min_ms, 0.0) << s.fault << ": the relay opened before the fault was visible?";
    EXPECT_GE(s.max_ms, s.min_ms) << s.fault;
  }
}

INSTANTIATE_TEST_SUITE_P(BothFixtures, SafetyBenchFixture, ::testing::Values("sim", "modbus"));

}  // namespace
}  // namespace eol::station
