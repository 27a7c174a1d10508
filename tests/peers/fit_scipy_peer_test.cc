// Cross-check of FitMotionalResonance against an independent peer: SciPy's
// least_squares(method='lm') on the same model, weighting and log parameters
// (tests/peers/fit_scipy_peer.py), run with /usr/bin/python3 on a noisy FRF written to CSV.
// python3-scipy is a declared dependency: if it is missing the test fails, it does not skip.
//
// Agreement required for every parameter: within 1e-3 relative AND within 0.05 of our reported
// sigma (both estimators find the same optimum of the same cost, so both hold with a wide
// margin); reported sigmas within 1 %; chi2 within 1e-6 relative.
#include <gtest/gtest.h>
#include <stdlib.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <locale>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>
#include <string>

#include "analysis/fit/resonance_fit.h"
#include "analysis/model/motor_model.h"

namespace eol::analysis {
namespace {

constexpr const char* kPython = "/usr/bin/python3";

// A fresh directory under the system temp dir, removed with its contents on destruction.
class TempDir {
 public:
  TempDir() {
    std::string tmpl = (std::filesystem::temp_directory_path() / "eol_fit_scipy_XXXXXX").string();
    if (mkdtemp(tmpl.data()) != nullptr) path_ = tmpl;
  }
  ~TempDir() {
    std::error_code ec;
    if (!path_.empty()) std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

struct CommandResult {
  int exit_code = -1;
  std::string output;  // stdout and stderr
};

CommandResult RunCommand(const std::string& command) {
  CommandResult r;
  FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  if (pipe == nullptr) return r;
  char buf[4096];
  std::size_t n;
  while ((n = fread(buf, 1, sizeof buf, pipe)) > 0) r.output.append(buf, n);
  const int status = pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return r;
}

std::string Quote(const std::string& s) { return "'" + s + "'"; }

TEST(FitScipyPeerTest, AgreesWithScipyLeastSquares) {
  ASSERT_EQ(access(kPython, X_OK), 0)
      << kPython << " not found: python3 with python3-scipy is a declared dependency";
  const std::string script = std::string(EOL_SOURCE_DIR) + "/tests/peers/fit_scipy_peer.py";
  ASSERT_TRUE(std::filesystem::exists(script)) << script;

  MotionalImpedance truth;
  truth.r_ohm = 0.5;
  truth.l_h = 2e-3;
  truth.rp_ohm = 0.5;
  truth.f0_hz = 390.0;
  truth.q = 50.0;
  std::vector<double> f;
  for (int k = 200; k <= 800; ++k) f.push_back(k);
  const double sigma = 0.02;
  Frf z = truth.Evaluate(f);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> noise(0.0, sigma / std::sqrt(2.0));
  for (auto& v : z.value) v += std::complex<double>(noise(rng), noise(rng));
  z.sigma.assign(f.size(), sigma);

  const FitSummary ours = FitMotionalResonance(z, ResonanceFitOptions{});
  ASSERT_TRUE(ours.usable) << ours.message;

  TempDir dir;
  ASSERT_FALSE(dir.path().empty()) << "cannot create a temporary directory";
  const std::filesystem::path csv = dir.path() / "frf.csv";
  {
    std::ofstream out(csv);
    out.imbue(std::locale::classic());
    out.precision(17);
    out << "freq_hz,re_ohm,im_ohm,sigma_ohm\n";
    for (std::size_t k = 0; k < z.size(); ++k)
      out << z.freq_hz[k] << ',' << z.value[k].real() << ',' << z.value[k].imag() << ','
          << z.sigma[k] << '\n';
    ASSERT_TRUE(out.good()) << "cannot write " << csv;
  }
  std::ostringstream cmd;
  cmd.imbue(std::locale::classic());
  cmd.precision(17);
  cmd << kPython << ' ' << Quote(script) << ' ' << Quote(csv.string()) << ' ' << truth.r_ohm << ' '
      << truth.l_h << ' ' << truth.rp_ohm << ' ' << truth.f0_hz << ' ' << truth.q;
  const CommandResult peer = RunCommand(cmd.str());
  ASSERT_NE(peer.exit_code, 2) << "python3-scipy is a declared dependency and is missing "
                                  "(apt-get install python3-scipy): "
                               << peer.output;
  ASSERT_EQ(peer.exit_code, 0) << cmd.str() << "\n" << peer.output;

  const nlohmann::json j = nlohmann::json::parse(peer.output, nullptr, /*allow_exceptions=*/false);
  ASSERT_FALSE(j.is_discarded()) << "peer output is not JSON: " << peer.output;
  ASSERT_TRUE(j.contains("params") && j.contains("sigma")) << peer.output;
  std::printf("scipy %s, status %d (%s), nfev %d; chi2 ours %.9g, scipy %.9g\n",
              j.value("scipy_version", "?").c_str(), j.value("status", -1),
              j.value("message", "").c_str(), j.value("nfev", -1), ours.chi2, j.value("chi2", 0.0));

  for (const char* name : {"R_ohm", "L_h", "Rp_ohm", "f0_hz", "Q"}) {
    const FittedParameter* p = ours.Find(name);
    ASSERT_NE(p, nullptr) << name;
    const double v = j["params"].value(name, std::nan(""));
    const double s = j["sigma"].value(name, std::nan(""));
    const double diff = std::abs(p->value - v);
    std::printf("%-7s ours %.12g +- %.4g, scipy %.12g +- %.4g: diff %.3g (%.2g sigma)\n", name,
                p->value, p->sigma, v, s, diff, diff / p->sigma);
    EXPECT_LE(diff, 1e-3 * std::abs(v)) << name;
    EXPECT_LE(diff, 0.05 * p->sigma) << name;
    EXPECT_NEAR(p->sigma / s, 1.0, 0.01) << name;
  }
  EXPECT_NEAR(ours.chi2 / j.value("chi2", std::nan("")), 1.0, 1e-6);
  EXPECT_EQ(ours.dof, j.value("dof", -1));
}

}  // namespace
}  // namespace eol::analysis
