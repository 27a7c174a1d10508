// `eol pod` through the built binary: what it refuses and says (the fit itself is checked in
// tests/analysis/pod_test.cc and against SciPy in tests/peers/pod_scipy_peer_test.cc). A hits
// file without a needed column or with a bad value is a usage/file error (exit 2) naming the
// file, line and column; a class whose hits and misses do not overlap has no estimate (exit 1,
// said per class) while the other class is still fitted.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::CliRun;

CliRun Pod(std::vector<std::string> args, bool merge_stderr = true) {
  args.insert(args.begin(), "pod");
  return testing::RunEol(std::move(args), merge_stderr, 60s);
}

TEST(PodCli, HitsFileErrorsNameTheCause) {
  eol::testing::TempDir dir;
  const std::string no_hit = dir / "no_hit.csv";
  std::ofstream(no_hit) << "size,result\n0.5,1\n";
  CliRun r = Pod({"--hits", no_hit});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(no_hit + ": the header has no column 'hit'"), std::string::npos) << r.out;

  const std::string bad_hit = dir / "bad_hit.csv";
  std::ofstream(bad_hit) << "size,hit\n0.5,1\n0.6,yes\n";
  r = Pod({"--hits", bad_hit});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(bad_hit + ":3: hit must be 0 or 1"), std::string::npos) << r.out;

  const std::string bad_size = dir / "bad_size.csv";
  std::ofstream(bad_size) << "size,hit\n0.5x,1\n";
  r = Pod({"--hits", bad_size});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find(bad_size + ":2 size: '0.5x' is not a number"), std::string::npos) << r.out;

  const std::string only_good = dir / "only_good.csv";
  std::ofstream(only_good) << "size,hit\n0,0\n0,0\n";
  r = Pod({"--hits", only_good});
  EXPECT_EQ(r.code, 2) << r.out;
  EXPECT_NE(r.out.find("no defective unit (size > 0)"), std::string::npos) << r.out;
}

TEST(PodCli, AClassWithoutAnEstimateIsSaidAndTheOthersFitted) {
  eol::testing::TempDir dir;
  const std::string hits = dir / "hits.csv";
  {
    std::ofstream out(hits);
    out << "class,size,hit\n";
    // "mixed": hits and misses overlap (a fit exists); "split": every miss below every hit.
    const double sizes[] = {0.3, 0.4, 0.5, 0.6, 0.7, 0.8};
    const int mixed[] = {0, 1, 0, 1, 1, 1};
    for (int i = 0; i < 6; ++i) out << "mixed," << sizes[i] << "," << mixed[i] << "\n";
    for (int i = 0; i < 6; ++i) out << "split," << sizes[i] << "," << (i >= 3 ? 1 : 0) << "\n";
  }
  CliRun r = Pod({"--hits", hits, "--json"}, false);
  EXPECT_EQ(r.code, 1) << r.out;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["pod"]["mixed"]["usable"].get<bool>()) << r.out;
  EXPECT_FALSE(j["pod"]["split"]["usable"].get<bool>()) << r.out;
  EXPECT_NE(j["pod"]["split"]["message"].get<std::string>().find("do not overlap"),
            std::string::npos)
      << r.out;
  r = Pod({"--hits", hits});
  EXPECT_EQ(r.code, 1) << r.out;
  EXPECT_NE(r.out.find("split: hits and misses do not overlap"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("mixed: logit POD on a from 6 units"), std::string::npos) << r.out;
}

}  // namespace
}  // namespace eol
