// Cross-check of EstimateWelchFrf (analysis/signal/welch.h) against an independent peer:
// scipy.signal.csd / welch / coherence (tests/peers/welch_scipy_peer.py) on the same samples,
// written to a CSV, with the same window (periodic Hann), segment, overlap and detrending.
// The maths is identical (only FFT rounding differs), so H1, H2 agree to 1e-9 relative and the
// coherence to 1e-9 absolute. python3-scipy is a declared dependency: if it is missing the
// test fails, it does not skip.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <complex>
#include <filesystem>
#include <fstream>
#include <locale>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "analysis/signal/welch.h"
#include "tests/support/child_process.h"

namespace eol::analysis {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

std::string Num(double v) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(17);
  os << v;
  return os.str();
}

TEST(WelchScipyPeerTest, H1H2AndCoherenceAgreeWithScipy) {
  ASSERT_EQ(access(kPython, X_OK), 0)
      << kPython << " not found: python3 with python3-scipy is a declared dependency";
  const std::string script = std::string(EOL_SOURCE_DIR) + "/tests/peers/welch_scipy_peer.py";
  ASSERT_TRUE(std::filesystem::exists(script)) << script;

  // A lightly damped resonance (a two-pole IIR) driven by noise, with noise on both channels.
  const double fs = 2000.0;
  const std::size_t n = 60000;
  std::mt19937_64 rng(17);
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<double> x(n), y(n);
  const double r = 0.995, theta = 2.0 * 3.141592653589793 * 150.0 / fs;
  double y1 = 0.0, y2 = 0.0;
  for (std::size_t t = 0; t < n; ++t) {
    const double u = g(rng);
    const double v = u + 2.0 * r * std::cos(theta) * y1 - r * r * y2;
    y2 = y1;
    y1 = v;
    x[t] = u + 0.1 * g(rng);
    y[t] = 0.05 * v + 0.2 * g(rng);
  }
  ChannelPair pair;
  pair.sample_rate_hz = fs;
  pair.x = x;
  pair.y = y;
  pair.quantity = Quantity::kMobility;
  WelchOptions o;
  o.segment_samples = 1000;
  o.overlap = 0.5;
  o.f_lo_hz = 10.0;
  o.f_hi_hz = 900.0;
  o.min_coherence = 0.0;
  const WelchSummary h1 = EstimateWelchFrf(pair, o);
  ASSERT_TRUE(h1.usable) << h1.message;
  o.estimator = WelchEstimator::kH2;
  const WelchSummary h2 = EstimateWelchFrf(pair, o);
  ASSERT_TRUE(h2.usable) << h2.message;

  eol::testing::TempDir dir;
  const std::string csv = dir / "xy.csv";
  {
    std::ofstream out(csv);
    out.imbue(std::locale::classic());
    out.precision(17);
    out << "x,y\n";
    for (std::size_t t = 0; t < n; ++t) out << x[t] << ',' << y[t] << '\n';
    ASSERT_TRUE(out.good()) << "cannot write " << csv;
  }
  // The estimator's overlap rule (welch.h): noverlap = floor(overlap M).
  const auto noverlap =
      static_cast<std::size_t>(std::floor(o.overlap * static_cast<double>(o.segment_samples)));
  eol::testing::ChildProcess peer({kPython, script, csv, Num(fs), std::to_string(o.segment_samples),
                                   std::to_string(noverlap), Num(o.f_lo_hz), Num(o.f_hi_hz)},
                                  /*merge_stderr=*/false);
  const auto code = peer.Wait(std::chrono::seconds(120));
  ASSERT_TRUE(code.has_value()) << "scipy peer did not finish in 120 s";
  ASSERT_NE(*code, 2) << "python3-scipy is a declared dependency and is missing "
                         "(apt-get install python3-scipy): "
                      << peer.output();
  ASSERT_EQ(*code, 0) << peer.output();
  const nlohmann::json j = nlohmann::json::parse(peer.output(), nullptr, false);
  ASSERT_FALSE(j.is_discarded()) << "peer output is not JSON: " << peer.output();
  const auto f = j.at("f_hz").get<std::vector<double>>();
  ASSERT_EQ(f.size(), h1.frf.size());
  double worst_h1 = 0.0, worst_h2 = 0.0, worst_coh = 0.0;
  for (std::size_t k = 0; k < f.size(); ++k) {
    EXPECT_NEAR(f[k], h1.frf.freq_hz[k], 1e-9) << k;
    const std::complex<double> s1(j["h1_re"][k].get<double>(), j["h1_im"][k].get<double>());
    const std::complex<double> s2(j["h2_re"][k].get<double>(), j["h2_im"][k].get<double>());
    worst_h1 = std::max(worst_h1, std::abs(h1.frf.value[k] - s1) / std::abs(s1));
    worst_h2 = std::max(worst_h2, std::abs(h2.frf.value[k] - s2) / std::abs(s2));
    worst_coh = std::max(worst_coh, std::abs(h1.coherence[k] - j["coherence"][k].get<double>()));
  }
  std::printf("scipy %s, %zu bins: worst relative difference H1 %.2g, H2 %.2g; coherence %.2g\n",
              j.value("scipy_version", "?").c_str(), f.size(), worst_h1, worst_h2, worst_coh);
  EXPECT_LT(worst_h1, 1e-9);
  EXPECT_LT(worst_h2, 1e-9);
  EXPECT_LT(worst_coh, 1e-9);
}

}  // namespace
}  // namespace eol::analysis
