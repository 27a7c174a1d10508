// `eol pod` (analysis/qc/pod.h) against an independent peer: tests/peers/pod_scipy_peer.py,
// the same MIL-HDBK-1823A hit/miss statement fitted with SciPy (BFGS + Nelder-Mead, brentq),
// run with /usr/bin/python3 on one hit/miss file with two classes (fixed seed; one class on
// x = a, the whole file again on x = ln a). python3-scipy is a declared dependency: if it is
// missing the test fails, it does not skip.
// Agreement: b0, b1 and a90 within 1e-5 relative (the same optimum of the same likelihood;
// Nelder-Mead stops near 1e-7); a90/95 by the likelihood ratio and by Wald within 1e-4
// relative (root finding on top of the optimum in both).
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <tuple>

#include "tests/support/child_process.h"

namespace eol::testing {
namespace {

std::string RunChild(const std::vector<std::string>& argv, int* code) {
  ChildProcess p(argv, false);
  *code = p.Wait(std::chrono::seconds(120)).value_or(-1);
  return p.output();
}

void ExpectRel(double ours, double peer, double tol, const std::string& what) {
  EXPECT_NEAR(ours, peer, tol * std::abs(peer)) << what;
}

TEST(PodScipyPeer, AgreesWithScipy) {
  ASSERT_EQ(access("/usr/bin/python3", X_OK), 0) << "python3 with python3-scipy is required";
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() /
      ("eol_pod_peer_" + std::to_string(getpid()) + "_" +
       std::to_string(std::chrono::steady_clock::now().time_since_epoch().count()));
  std::filesystem::create_directories(dir);
  const std::string hits = (dir / "hits.csv").string();
  {
    // Two classes with true logistic POD curves (a50, a90) over a uniform 0.2-0.99, and good
    // units (size 0: not fitted).
    std::mt19937_64 gen(2026);
    std::uniform_real_distribution<double> size(0.2, 0.99), u(0.0, 1.0);
    std::ofstream out(hits);
    out << "class,size,hit,f0_hz\n";
    const std::tuple<const char*, double, double> classes[] = {{"one", 0.9, 0.97},
                                                               {"all", 0.8, 0.9}};
    for (const auto& [cls, a50, a90] : classes) {
      const double b1 = std::log(9.0) / (a90 - a50), b0 = -a50 * b1;
      for (int i = 0; i < 300; ++i) {
        const double a = size(gen);
        const bool hit = u(gen) < 1.0 / (1.0 + std::exp(-(b0 + b1 * a)));
        out << cls << "," << a << "," << hit << "," << 390.0 - 30.0 * std::pow(a, 8) << "\n";
      }
    }
    for (int i = 0; i < 50; ++i) out << "good,0,0," << 388.0 + 0.1 * i << "\n";
  }
  for (const bool log : {false, true}) {
    int code = 0;
    std::vector<std::string> eol = {EOL_BINARY, "pod", "--hits", hits, "--json"};
    std::vector<std::string> peer = {
        "/usr/bin/python3", std::string(EOL_SOURCE_DIR) + "/tests/peers/pod_scipy_peer.py", hits};
    if (log) {
      eol.insert(eol.end(), {"--scale", "log"});
      peer.push_back("--log");
    }
    const std::string ours_text = RunChild(eol, &code);
    ASSERT_EQ(code, 0) << ours_text;
    const std::string peer_text = RunChild(peer, &code);
    ASSERT_EQ(code, 0) << peer_text;
    const auto ours = nlohmann::json::parse(ours_text).at("pod");
    const auto theirs = nlohmann::json::parse(peer_text);
    ASSERT_EQ(ours.size(), 2u) << ours.dump(1);  // good units are not fitted
    for (const char* cls : {"one", "all"}) {
      const auto& o = ours.at(cls);
      const auto& t = theirs.at(cls);
      const std::string what = std::string(cls) + (log ? " log" : " linear") + "\nours " +
                               o.dump() + "\npeer " + t.dump();
      ASSERT_TRUE(o.at("usable").get<bool>()) << what;
      ExpectRel(o.at("b0"), t.at("b0"), 1e-5, what);
      ExpectRel(o.at("b1"), t.at("b1"), 1e-5, what);
      ExpectRel(o.at("log_likelihood"), t.at("log_likelihood"), 1e-9, what);
      ExpectRel(o.at("a90"), t.at("a90"), 1e-5, what);
      ASSERT_FALSE(o.at("a90_95_lr").is_null()) << what;
      ASSERT_FALSE(t.at("a90_95_lr").is_null()) << what;
      ExpectRel(o.at("a90_95_lr"), t.at("a90_95_lr"), 1e-4, what);
      ExpectRel(o.at("a90_95_wald"), t.at("a90_95_wald"), 1e-4, what);
    }
  }
  // The figure: POD panel and f0 panel with the limit drawn.
  int code = 0;
  const std::string svg = (dir / "pod.svg").string();
  RunChild({EOL_BINARY, "pod", "--hits", hits, "--pod-svg", svg, "--f0-limit", "380"}, &code);
  EXPECT_EQ(code, 0);
  std::ifstream in(svg);
  const std::string doc((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(doc.find("<svg"), std::string::npos);
  EXPECT_NE(doc.find("a90/95"), std::string::npos) << doc.substr(0, 2000);
  EXPECT_NE(doc.find("f0 limit 380.00 Hz"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace eol::testing
