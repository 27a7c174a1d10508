// Inputs the fuzzers (tests/fuzz/, tests/README.md "Fuzzing") found to break a reader's contract in
// drivers/io, each kept here as a test that fails without its fix. The inputs are in the
// seed corpora too (tests/fuzz/corpus/<target>/finding-*).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include "drivers/io/file_error.h"
#include "drivers/io/json_config.h"
#include "drivers/io/recording_files.h"
#include "tests/support/child_process.h"

namespace eol::io {
namespace {

// recipe_fuzzer and config_fuzzer: a number beyond double's range is a JSON error
// (nlohmann's out_of_range.406), which escaped ParseJsonText as an undocumented exception.
TEST(FuzzRegressions, ANumberBeyondDoubleIsAConfigErrorNamingTheFile) {
  eol::testing::TempDir dir;
  const std::string path = dir / "recipe.json";
  std::ofstream(path) << R"({"id": "x", "version": 444e444})";
  try {
    ReadJsonFile(path);
    FAIL() << "1e444 was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": not valid JSON: ", 0), 0u) << e.what();
    EXPECT_NE(std::string(e.what()).find("number overflow parsing '444e444'"), std::string::npos)
        << e.what();
  }
}

std::string FileErrorOf(const std::function<void()>& read) {
  try {
    read();
  } catch (const FileError& e) {
    return e.what();
  }
  return "";
}

// recording_csv_fuzzer's contract: times near the ends of double's range gave an infinite
// span, which passed the grid check and made the rate 0, or a subnormal step and an
// infinite rate.
TEST(FuzzRegressions, RecordingTimesWithoutAFiniteSampleRateAreRefused) {
  eol::testing::TempDir dir;
  const std::string wide = dir / "wide.csv", tiny = dir / "tiny.csv";
  std::ofstream(wide) << "t_s,u_v,i_a\n-1e308,1,1\n1e308,1,1\n";
  std::ofstream(tiny) << "t_s,u_v,i_a\n0,1,1\n5e-324,1,1\n";
  EXPECT_EQ(FileErrorOf([&] { ReadRecordingCsv(wide); }),
            wide + ":3:1: t_s: the sample interval inf s gives no finite sample rate");
  EXPECT_EQ(FileErrorOf([&] { ReadRecordingCsv(tiny); }),
            tiny + ":3:1: t_s: the sample interval 4.94066e-324 s gives no finite sample rate");
}

// wav_fuzzer's contract: a float WAV can hold NaN and infinities, which went into the
// recording (the CSV reader refuses them).
TEST(FuzzRegressions, AWavSampleThatIsNotFiniteIsRefusedNamingTheFrame) {
  eol::testing::TempDir dir;
  const std::string path = dir / "nan.wav";
  analysis::Recording r;
  r.sample_rate_hz = 8000;
  r.voltage_v = {0.5, 0.25, 0.125};
  r.current_a = {0.1, std::numeric_limits<double>::infinity(), 0.2};
  WriteWavRecording(path, r, 1.0, 1.0);
  EXPECT_EQ(FileErrorOf([&] { ReadWavRecording(path, 10.0, 5.0); }),
            path + ": frame 1: the current sample is not a finite number once scaled by its gain");
  r.current_a[1] = 0.3;
  WriteWavRecording(path, r, 1.0, 1.0);
  EXPECT_EQ(ReadWavRecording(path, 10.0, 5.0).current_a.at(1), 0.3f * 5.0);
}

// wav_fuzzer in the suite's run: a malformed header whose samples read back finite but
// overflow once scaled by the gain (kept as tests/fuzz/corpus/wav/finding-scaled-overflow.wav).
TEST(FuzzRegressions, AWavSampleThatOverflowsOnceScaledIsRefused) {
  const std::string path =
      std::string(EOL_SOURCE_DIR) + "/tests/fuzz/corpus/wav/finding-scaled-overflow.wav";
  const std::string e = FileErrorOf([&] { ReadWavRecording(path, 10.0, 5.0); });
  EXPECT_NE(e.find("is not a finite number once scaled by its gain"), std::string::npos) << e;
}

// recipe_fuzzer and config_fuzzer's check that whole numbers are kept: get<int>() wrapped,
// so "periods": 4294967300 was read as 4 and "port": 4294975376 as 8080.
TEST(FuzzRegressions, AWholeNumberBeyondIntIsRefusedNotWrapped) {
  const nlohmann::json j = nlohmann::json::parse(
      R"({"periods": 4294967300, "port": 4294975376, "low": -2147483649, "max": 2147483647,
          "min": -2147483648})");
  const JsonObject o(j, "/excitation");
  for (const char* key : {"periods", "port", "low"}) {
    try {
      o.Integer(key, 0);
      FAIL() << key << " was accepted";
    } catch (const ConfigError& e) {
      EXPECT_EQ(std::string(e.what()), "/excitation/" + std::string(key) +
                                           ": must be a whole number in [-2147483648, "
                                           "2147483647] (got " +
                                           j[key].dump() + ")");
    }
  }
  EXPECT_EQ(o.Integer("max", 0), std::numeric_limits<int>::max());
  EXPECT_EQ(o.Integer("min", 0), std::numeric_limits<int>::min());
}

}  // namespace
}  // namespace eol::io
