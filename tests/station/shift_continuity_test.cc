// Issue 36, shift continuity: a restarted station shows the store's last results and the
// day's counts, not an empty board. Real recipe, real SQLite file, the simulated bench.
#include <gtest/gtest.h>

#include <cctype>
#include <chrono>
#include <string>

#include "station/daemon/station.h"
#include "tests/support/child_process.h"

namespace eol::station {
namespace {

nlohmann::json Config(const eol::testing::TempDir& dir) {
  return {{"station_id", "continuity"},
          {"recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"},
          {"db", dir / "s.sqlite"},
          {"fixture", {{"driver", "sim"}}},
          {"daq", {{"driver", "sim"}}},
          {"sim", {{"clamp_close_s", 0.01}, {"clamp_open_s", 0.01}}}};
}

TEST(ShiftContinuity, ARestartShowsTheStoresLastResultsAndTheDaysCounts) {
  eol::testing::TempDir dir;
  std::vector<std::string> serials;
  nlohmann::json counts_before;
  {
    Station first(ParseStationConfig(Config(dir), "t", ""));
    for (int i = 1; i <= 3; ++i) {
      const db::TestRecord r = first.RunTest("SHIFT-" + std::to_string(i));
      ASSERT_GT(r.id, 0);
      serials.insert(serials.begin(), r.serial);  // newest first
    }
    counts_before = first.board().Snapshot()["counts"];
  }
  Station again(ParseStationConfig(Config(dir), "t", ""));
  const nlohmann::json s = again.board().Snapshot();
  ASSERT_EQ(s["recent"].size(), 3u) << s["recent"].dump();
  for (std::size_t i = 0; i < serials.size(); ++i) {
    EXPECT_EQ(s["recent"][i]["serial"], serials[i]);
    EXPECT_GT(s["recent"][i]["id"].get<long long>(), 0);
  }
  EXPECT_EQ(s["counts"], counts_before) << "the day's counts as before the restart";
  EXPECT_EQ(s["counts"]["day"], LocalDay(std::chrono::system_clock::now()));
  const auto n = s["counts"]["pass"].get<int>() + s["counts"]["fail"].get<int>() +
                 s["counts"]["error"].get<int>() + s["counts"]["aborted"].get<int>();
  EXPECT_EQ(n, 3);
  EXPECT_TRUE(s["last"].is_null()) << "the lamp stays empty: no unit was tested since the start";
  // The next verdict goes on from there.
  const db::TestRecord r = again.RunTest("SHIFT-4");
  const nlohmann::json after = again.board().Snapshot();
  EXPECT_EQ(after["recent"][0]["serial"], "SHIFT-4");
  EXPECT_EQ(after["recent"].size(), 4u);
  std::string key = analysis::ToString(r.outcome);  // "PASS" -> "pass"
  for (char& ch : key) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  EXPECT_EQ(after["counts"][key].get<int>(), counts_before[key].get<int>() + 1) << key;
}

TEST(ShiftContinuity, LocalMidnightIsTheStartOfTheLocalDay) {
  const auto now = std::chrono::system_clock::now();
  const auto midnight = LocalMidnight(now);
  EXPECT_LE(midnight, now);
  EXPECT_GT(midnight, now - std::chrono::hours(25));
  EXPECT_EQ(LocalDay(midnight), LocalDay(now));
  EXPECT_NE(LocalDay(midnight - std::chrono::seconds(1)), LocalDay(now));
}

}  // namespace
}  // namespace eol::station
