// Inputs the fuzzers (tests/fuzz/, README "Fuzzing") found to break a reader's contract in
// drivers/io, each kept here as a test that fails without its fix. The inputs are in the
// seed corpora too (tests/fuzz/corpus/<target>/finding-*).
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "drivers/io/json_config.h"
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

}  // namespace
}  // namespace eol::io
