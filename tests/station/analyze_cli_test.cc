// `eol analyze` through the binary (EOL_BINARY) on files generated here from the reference
// motor (analysis::MotionalImpedance + noise, or a simulated periodic recording): JSON
// contents, the noise-estimated notice, verdicts from the recipe, and the exit codes
// (0 analysed, 1 cannot be analysed, 2 usage or file error).
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "analysis/bench/fit_bench.h"
#include "analysis/model/motor_model.h"
#include "analysis/model/two_mass.h"
#include "analysis/signal/chirp_noise.h"
#include "analysis/sim/steady_state.h"
#include "analysis/text.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/recording_files.h"
#include "tests/support/child_process.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

#define EXPECT_CONTAINS(haystack, needle) \
  EXPECT_PRED_FORMAT2(::testing::IsSubstring, needle, haystack)

const std::string kRecipe = std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json";
const analysis::MotionalImpedance kGood{0.5, 2.0e-3, 0.51, 390.0, 50.0};

using eol::testing::CliRun;

CliRun Eol(std::vector<std::string> args, bool merge_stderr = false) {
  args.insert(args.begin(), "analyze");
  return testing::RunEol(std::move(args), merge_stderr, std::chrono::seconds(120));
}

nlohmann::json Json(const CliRun& r) {
  const nlohmann::json j = nlohmann::json::parse(r.out, nullptr, false);
  EXPECT_FALSE(j.is_discarded()) << "not JSON: " << r.out;
  return j;
}

analysis::Frf NoisyZ(const analysis::MotionalImpedance& m, double sigma, bool keep_sigma,
                     std::uint64_t seed) {
  std::vector<double> f;
  for (int k = 200; k <= 800; ++k) f.push_back(k);
  analysis::Frf z = m.Evaluate(f);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> n(0.0, sigma / std::sqrt(2.0));
  for (auto& v : z.value) v += std::complex<double>(n(rng), n(rng));
  if (keep_sigma) z.sigma.assign(f.size(), sigma);
  return z;
}

TEST(AnalyzeCliTest, FrfCsvWithSigmaJson) {
  testing::TempDir dir;
  io::WriteFrfCsv(dir / "z.csv", NoisyZ(kGood, 0.02, true, 1));
  const CliRun r = Eol({"--measured", dir / "z.csv", "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = Json(r);
  const double f = j["resonance"]["f_hz"], s = j["resonance"]["f_sigma_hz"];
  EXPECT_NEAR(f, 390.0, 4.0 * s);
  EXPECT_GT(s, 0.0);
  EXPECT_NEAR(j["resonance"]["q"].get<double>(), 50.0,
              4.0 * j["resonance"]["q_sigma"].get<double>());
  for (const char* p : {"R_ohm", "L_h", "Rp_ohm", "f0_hz", "Q"}) {
    ASSERT_TRUE(j["params"].contains(p)) << p;
    EXPECT_GT(j["params"][p]["sigma"].get<double>(), 0.0) << p;
    EXPECT_TRUE(j["params"][p].contains("unit")) << p;
  }
  EXPECT_NEAR(j["params"]["R_ohm"]["value"].get<double>(), 0.5, 0.01);
  EXPECT_NEAR(j["fit"]["chi2_per_dof"].get<double>(), 1.0, 0.15);
  EXPECT_EQ(j["fit"]["model"], "R+sL+parallel-RLC");
  EXPECT_EQ(j["noise_estimated"], false);
  EXPECT_FALSE(j.contains("verdict"));
}

TEST(AnalyzeCliTest, WithoutSigmaSaysNoiseIsEstimated) {
  testing::TempDir dir;
  io::WriteFrfCsv(dir / "z.csv", NoisyZ(kGood, 0.02, false, 2));
  const CliRun j = Eol({"--measured", dir / "z.csv", "--json"});
  ASSERT_EQ(j.code, 0) << j.out;
  EXPECT_EQ(Json(j)["noise_estimated"], true);
  EXPECT_NEAR(Json(j)["estimated_sigma_ohm"].get<double>(), 0.02, 0.002);
  const CliRun t = Eol({"--measured", dir / "z.csv"});
  ASSERT_EQ(t.code, 0) << t.out;
  EXPECT_CONTAINS(t.out, "noise: the file has no sigma; estimated from the fit residual");
  EXPECT_CONTAINS(t.out, "resonance: f0 = 390.");
}

TEST(AnalyzeCliTest, RecipeGivesVerdictPassAndFail) {
  testing::TempDir dir;
  io::WriteFrfCsv(dir / "good.csv", NoisyZ(kGood, 0.02, true, 3));
  analysis::MotionalImpedance soft = kGood;
  soft.f0_hz = 350.0;
  io::WriteZma(dir / "soft.zma", NoisyZ(soft, 0.02, false, 4));
  const CliRun g = Eol({"--measured", dir / "good.csv", "--recipe", kRecipe, "--json"});
  ASSERT_EQ(g.code, 0) << g.out;
  const nlohmann::json jg = Json(g);
  EXPECT_EQ(jg["verdict"]["outcome"], "PASS") << jg["verdict"].dump();
  EXPECT_GE(jg["verdict"]["measurements"].size(), 5u);
  EXPECT_EQ(jg["recipe"]["id"], "pmsm-10pole");
  const CliRun s = Eol({"--measured", dir / "soft.zma", "--recipe", kRecipe, "--json"});
  ASSERT_EQ(s.code, 0) << s.out;  // analysed: a FAIL is a result
  const nlohmann::json js = Json(s);
  EXPECT_EQ(js["format"], "zma");
  EXPECT_EQ(js["noise_estimated"], true);
  EXPECT_EQ(js["verdict"]["outcome"], "FAIL");
  EXPECT_CONTAINS(js["verdict"]["reasons"].dump(), "resonance_f_hz");
}

TEST(AnalyzeCliTest, RawRecordingCsvAndWav) {
  testing::TempDir dir;
  analysis::MultisineOptions o;  // the recipe's excitation
  const analysis::Excitation e = analysis::DesignMultisine(o);
  const analysis::Recording rec = analysis::SimulatePeriodicRecording(kGood, e, 5, 2e-3, 1e-3, 9);
  io::WriteRecordingCsv(dir / "rec.csv", rec);
  io::WriteWavRecording(dir / "rec.wav", rec, 4.0, 1.0);
  for (const std::vector<std::string>& extra :
       {std::vector<std::string>{"--measured", dir / "rec.csv", "--recipe", kRecipe},
        {"--measured", dir / "rec.csv", "--excitation-band", "200,800,1"},
        {"--measured", dir / "rec.csv", "--period-samples", "8000", "--lines", "200:800"},
        {"--measured", dir / "rec.wav", "--recipe", kRecipe, "--voltage-gain", "4",
         "--current-gain", "1"}}) {
    std::vector<std::string> args = extra;
    args.push_back("--json");
    const CliRun r = Eol(args);
    ASSERT_EQ(r.code, 0) << r.out;
    const nlohmann::json j = Json(r);
    EXPECT_EQ(j["frf"]["periods_used"], 4);
    EXPECT_EQ(j["lines"], 601);
    EXPECT_EQ(j["noise_estimated"], false);
    EXPECT_NEAR(j["resonance"]["f_hz"].get<double>(), 390.0,
                4.0 * j["resonance"]["f_sigma_hz"].get<double>());
    EXPECT_LT(j["fit"]["chi2_per_dof"].get<double>(), 1.5);
  }
}

// A raw recording whose current clipped the DAQ's range (16-bit converter, range 0.6 of the
// current's peak) is ERROR "current clipped at X A" (code "clipped") before any fit, with
// the range unknown to the file (samples repeated at the rail), stated in the CSV's
// i_full_scale_a column, or given by --current-full-scale; the unclipped recording of the
// same motor passes the same way.
TEST(AnalyzeCliTest, ClippedRecordingIsErrorClippedBeforeAnyFit) {
  testing::TempDir dir;
  const analysis::Excitation e = analysis::DesignMultisine(analysis::MultisineOptions{});
  const analysis::Recording clean =
      analysis::SimulatePeriodicRecording(kGood, e, 5, 2e-3, 1e-3, 11);
  double peak = 0.0;
  for (double i : clean.current_a) peak = std::max(peak, std::abs(i));
  const double i_fs = 0.6 * peak;
  analysis::Recording rec = clean;
  for (auto [x, fs] : {std::pair{&rec.voltage_v, 10.0}, std::pair{&rec.current_a, i_fs}}) {
    const double lsb = fs / 32768.0;
    for (double& v : *x) v = std::clamp(std::round(v / lsb), -32768.0, 32767.0) * lsb;
  }
  io::WriteRecordingCsv(dir / "clipped.csv", rec);
  {
    std::ofstream stated(dir / "stated.csv");
    stated.precision(17);
    stated << "t_s,u_v,i_a,u_full_scale_v,i_full_scale_a\n";
    for (std::size_t k = 0; k < rec.voltage_v.size(); ++k)
      stated << static_cast<double>(k) / rec.sample_rate_hz << ',' << rec.voltage_v[k] << ','
             << rec.current_a[k] << ",10," << i_fs << '\n';
  }
  io::WriteRecordingCsv(dir / "clean.csv", clean);
  const auto check = [&](const std::vector<std::string>& args, const std::string& rule) {
    std::vector<std::string> all = args;
    for (const char* a : {"--recipe", "--json"}) all.push_back(a);
    all.insert(all.end() - 1, kRecipe);
    const CliRun r = Eol(all);
    EXPECT_EQ(r.code, 1) << r.out;
    const nlohmann::json j = Json(r);
    EXPECT_EQ(j["verdict"]["outcome"], "ERROR");
    ASSERT_EQ(j["verdict"]["reasons"].size(), 1u) << j["verdict"].dump();
    const nlohmann::json& reason = j["verdict"]["reasons"][0];
    EXPECT_EQ(reason["code"], "clipped");
    const std::string text = reason["text"];
    EXPECT_EQ(text.rfind("invalid measurement: current clipped at ", 0), 0u) << text;
    EXPECT_CONTAINS(text, rule);
    EXPECT_EQ(text.find("voltage clipped"), std::string::npos) << text;
    EXPECT_FALSE(j.contains("params")) << "fitted: " << j.dump();  // before any fit
    EXPECT_EQ(j["verdict"]["measurements"].size(), 0u);
  };
  check({"--measured", dir / "clipped.csv"}, "a converter rail");
  check({"--measured", dir / "stated.csv"}, "of the converter's full scale");
  check({"--measured", dir / "clean.csv", "--current-full-scale", analysis::Fixed(i_fs, 6)},
        "of the converter's full scale");
  const CliRun text = Eol({"--measured", dir / "clipped.csv", "--recipe", kRecipe}, true);
  EXPECT_EQ(text.code, 1);
  EXPECT_CONTAINS(text.out, "eol analyze: invalid measurement: current clipped at ");
  const CliRun ok = Eol({"--measured", dir / "clean.csv", "--recipe", kRecipe, "--json"});
  ASSERT_EQ(ok.code, 0) << ok.out;
  EXPECT_EQ(Json(ok)["verdict"]["outcome"], "PASS") << Json(ok)["verdict"].dump();
  const CliRun frf = Eol({"--measured", dir / "clean.csv", "--voltage-full-scale", "-1"}, true);
  EXPECT_EQ(frf.code, 2) << frf.out;
}

// Random excitation: band-limited noise through the motor (the record's circular steady state,
// a linear response apart from the wrap at the record's ends), Welch H1 with 2 s segments
// (>= 8 / B3dB, analysis/README.md 3), sigma from the coherence.
TEST(AnalyzeCliTest, NoiseRecordingWithWelch) {
  testing::TempDir dir;
  analysis::NoiseOptions n;
  n.samples = 30 * 8000;
  const analysis::NoiseSignal u = analysis::GenerateBandLimitedNoise(n);
  analysis::Recording rec;
  rec.sample_rate_hz = n.sample_rate_hz;
  rec.voltage_v = u.samples_v;
  rec.current_a = analysis::SteadyStateCurrent([](double f) { return kGood.At(f); }, u.samples_v,
                                               n.sample_rate_hz);
  std::mt19937_64 rng(8);
  std::normal_distribution<double> vn(0.0, 2e-3), in(0.0, 1e-3);
  for (std::size_t t = 0; t < rec.voltage_v.size(); ++t) {
    rec.voltage_v[t] += vn(rng);
    rec.current_a[t] += in(rng);
  }
  io::WriteWavRecording(dir / "noise.wav", rec, 4.0, 1.0);
  const CliRun r = Eol({"--measured", dir / "noise.wav", "--voltage-gain", "4", "--current-gain",
                        "1", "--welch-segment", "16000", "--recipe", kRecipe, "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = Json(r);
  EXPECT_EQ(j["frf"]["method"], "welch-h1");
  EXPECT_EQ(j["noise_estimated"], false);
  EXPECT_NEAR(j["resonance"]["f_hz"].get<double>(), 390.0, 0.5);
  EXPECT_EQ(j["verdict"]["outcome"], "PASS") << j["verdict"].dump();
  const CliRun bad = Eol({"--measured", dir / "noise.wav", "--voltage-gain", "4", "--current-gain",
                          "1", "--welch-segment", "16000", "--lines", "3"});
  EXPECT_EQ(bad.code, 2);
}

TEST(AnalyzeCliTest, MobilityFrfGetsTheTwoMassFit) {
  testing::TempDir dir;
  analysis::TwoMassResponse m{105.0, 53.0, 77.0, 0.015, 0.0, 0.0};
  std::vector<double> f;
  for (int k = 11; k <= 250; ++k) f.push_back(k);
  analysis::Frf h = m.Evaluate(f);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (std::size_t k = 0; k < h.size(); ++k) {
    h.sigma.push_back(0.01 * std::abs(h.value[k]));
    h.value[k] += std::complex<double>(n(rng), n(rng)) * (h.sigma[k] / std::sqrt(2.0));
  }
  io::WriteFrfCsv(dir / "h.csv", h);
  const CliRun r = Eol({"--measured", dir / "h.csv", "--json"});
  ASSERT_EQ(r.code, 0) << r.out;
  const nlohmann::json j = Json(r);
  EXPECT_EQ(j["fit"]["model"], "two-mass");
  EXPECT_NEAR(j["resonance"]["f_hz"].get<double>(), 77.0, 0.5);
  EXPECT_NEAR(j["anti_resonance"]["f_hz"].get<double>(), 53.0, 0.5);
}

TEST(AnalyzeCliTest, DataThatCannotBeAnalysedExitsOne) {
  testing::TempDir dir;
  analysis::MotionalImpedance none = kGood;
  none.rp_ohm = 1e-9;  // T(phi) ~ 0: no coupling, no peak
  io::WriteFrfCsv(dir / "flat.csv", NoisyZ(none, 0.02, true, 6));
  const CliRun j = Eol({"--measured", dir / "flat.csv", "--recipe", kRecipe, "--json"});
  EXPECT_EQ(j.code, 1) << j.out;
  const nlohmann::json js = Json(j);
  EXPECT_CONTAINS(js["error"].get<std::string>(), "no resonance found");
  EXPECT_EQ(js["verdict"]["outcome"], "ERROR");
  const CliRun t = Eol({"--measured", dir / "flat.csv"}, /*merge_stderr=*/true);
  EXPECT_EQ(t.code, 1);
  EXPECT_CONTAINS(t.out, "eol analyze: fit not usable: no resonance found");
}

TEST(AnalyzeCliTest, UsageAndFileErrorsExitTwo) {
  testing::TempDir dir;
  const CliRun missing = Eol({"--measured", dir / "nope.csv"}, true);
  EXPECT_EQ(missing.code, 2);
  EXPECT_CONTAINS(missing.out, "nope.csv: cannot open");
  {
    std::ofstream bad(dir / "bad.csv");
    bad << "f_hz,re_ohm,im_ohm\n200,0.5,1\n201,oops,1\n";
  }
  const CliRun garbage = Eol({"--measured", dir / "bad.csv", "--json"}, true);
  EXPECT_EQ(garbage.code, 2);
  EXPECT_CONTAINS(garbage.out, "bad.csv:3:5: re_ohm: \\\"oops\\\" is not a number");
  analysis::Recording rec;
  rec.sample_rate_hz = 8000.0;
  rec.voltage_v.assign(100, 0.1);
  rec.current_a.assign(100, 0.01);
  io::WriteRecordingCsv(dir / "r.csv", rec);
  const CliRun no_excitation = Eol({"--measured", dir / "r.csv"}, true);
  EXPECT_EQ(no_excitation.code, 2);
  EXPECT_CONTAINS(no_excitation.out, "a raw recording needs its excitation");
  const CliRun no_file = Eol({}, true);
  EXPECT_EQ(no_file.code, 2);
  EXPECT_CONTAINS(no_file.out, "--measured FILE is required");
}

}  // namespace
}  // namespace eol
