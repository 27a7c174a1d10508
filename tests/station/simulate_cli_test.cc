// `eol simulate` through the built binary: the simulated FRF's resonance lands where the
// rotor chain says (390 Hz in the default fixture, 706 Hz rigid, 529 Hz rigid with every
// magnet poorly cemented, 366 Hz plus a magnet mode in the fixture), one soft magnet on a
// rigid fixture shows two modes, the recording
// format holds every sample, and errors name the option or JSON path.
#include <gtest/gtest.h>

#include <fstream>

#include "../support/child_process.h"
#include "analysis/fit/modes_fit.h"
#include "analysis/fit/resonance_fit.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/recording_files.h"
#include "tests/support/eol_cli.h"

namespace eol {
namespace {

using namespace std::chrono_literals;
using eol::testing::ChildProcess;

const std::string kMotors = std::string(EOL_SOURCE_DIR) + "/recipes/motors/";

using eol::testing::CliRun;

// The simulator's physics is checked at the shipped recipe's resolution (1 Hz lines, 4 s
// averaged): two weak modes and a band-edge mode need it (the 0.5 s recipe loses them).
CliRun Simulate(std::vector<std::string> args) {
  args.insert(args.begin(), "simulate");
  args.insert(args.end(), {"--recipe", std::string(EOL_SOURCE_DIR) + "/recipes/pmsm-10pole.json"});
  return testing::RunEol(std::move(args), true, 120s);
}

analysis::FitSummary Fit(const analysis::Frf& z, double lo, double hi) {
  analysis::ResonanceFitOptions o;
  o.f0_min_hz = lo;
  o.f0_max_hz = hi;
  return analysis::FitMotionalResonance(z, o);
}

void ExpectResonance(const std::string& motor, const std::string& defect, double f_chain, double lo,
                     double hi) {
  eol::testing::TempDir dir;
  const CliRun r =
      Simulate({"--motor", kMotors + motor, "--out", dir / "z.csv", "--defect", defect});
  ASSERT_EQ(r.code, 0) << r.out;
  const analysis::Frf z = io::ReadFrfCsv(dir / "z.csv");
  ASSERT_TRUE(z.has_sigma());
  EXPECT_EQ(z.size(), 601u);  // the recipe's 200-800 Hz at 1 Hz
  const analysis::FitSummary fit = Fit(z, lo, hi);
  ASSERT_TRUE(fit.usable) << fit.message;
  const analysis::FittedParameter* f0 = fit.Find("f0_hz");
  // The chain's mode within the fit's uncertainty (a tenth of a hertz here).
  EXPECT_NEAR(f0->value, f_chain, 5 * f0->sigma + 0.2)
      << motor << " " << defect << ": " << fit.message << "\n"
      << r.out;
  EXPECT_LT(fit.chi2_per_dof, 1.5) << fit.message;
}

TEST(SimulateCli, GoodRotorInTheDefaultFixtureRingsAt390Hz) {
  ExpectResonance("pmsm-10pole.json", "none", 390.0, 250, 700);
}

TEST(SimulateCli, RigidFixtureRingsAt706Hz) {
  ExpectResonance("pmsm-10pole-rigid.json", "none", 706.0, 250, 790);
}

TEST(SimulateCli, PoorCementationRigidRingsAt529Hz) {
  ExpectResonance("pmsm-10pole-rigid.json", "all_soft", 529.0, 250, 790);
}

TEST(SimulateCli, PoorCementationInTheFixtureRingsNear366HzWithAMagnetMode) {
  // Every bond poor in the default fixture: the rotor mode drops to 366 Hz and the magnets
  // ringing against the poles show at 753 Hz (Q 20): two modes in the band.
  eol::testing::TempDir dir;
  const CliRun r = Simulate(
      {"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "z.csv", "--defect", "all_soft"});
  ASSERT_EQ(r.code, 0) << r.out;
  analysis::ModesFitOptions o;
  o.single.f0_min_hz = 250;
  o.single.f0_max_hz = 790;
  const analysis::ModesFitSummary s = analysis::FitMotionalModes(io::ReadFrfCsv(dir / "z.csv"), o);
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_EQ(s.mode_count, 2) << s.message;
  EXPECT_NEAR(s.fit.Find("f1_hz")->value, 366.0, 0.5) << s.message;
  EXPECT_NEAR(s.fit.Find("f2_hz")->value, 752.8, 3.0) << s.message;
  EXPECT_LT(s.fit.chi2_per_dof, 1.5) << s.message;
}

TEST(SimulateCli, OneSoftMagnetOnARigidFixtureShowsTwoModes) {
  eol::testing::TempDir dir;
  const CliRun r = Simulate({"--motor", kMotors + "pmsm-10pole-rigid.json", "--out", dir / "z.csv",
                             "--defect", "one_soft_magnet", "--seed", "3"});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("567."), std::string::npos) << r.out;  // the stdout mode list
  analysis::ModesFitOptions o;
  o.single.f0_min_hz = 250;
  o.single.f0_max_hz = 790;
  const analysis::ModesFitSummary s = analysis::FitMotionalModes(io::ReadFrfCsv(dir / "z.csv"), o);
  ASSERT_TRUE(s.usable) << s.message;
  EXPECT_EQ(s.mode_count, 2) << s.message;
  EXPECT_NEAR(s.fit.Find("f1_hz")->value, 567.3, 2.0) << s.message;
  EXPECT_NEAR(s.fit.Find("f2_hz")->value, 723.7, 2.0) << s.message;
}

TEST(SimulateCli, RecordingFormatHoldsEveryPeriod) {
  eol::testing::TempDir dir;
  const CliRun r = Simulate(
      {"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "rec.csv", "--format", "recording"});
  ASSERT_EQ(r.code, 0) << r.out;
  std::ifstream in(dir / "rec.csv");
  std::string header;
  std::getline(in, header);
  EXPECT_EQ(header.rfind("t_s,u_v,i_a", 0), 0u) << header;
  const analysis::Recording rec = io::ReadRecordingCsv(dir / "rec.csv");
  EXPECT_EQ(rec.voltage_v.size(), 5u * 8000u);  // 1 transient + 4 averaged periods
  EXPECT_NEAR(rec.sample_rate_hz, 8000.0, 1e-6);
}

TEST(SimulateCli, NoCouplingAtAZeroOfTheTransmission) {
  // T = T_hat sin(5 phi) vanishes at 36 degrees: no motional peak, no resonance to find.
  eol::testing::TempDir dir;
  const CliRun r = Simulate({"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "z.csv",
                             "--rotor-position-deg", "36"});
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_FALSE(Fit(io::ReadFrfCsv(dir / "z.csv"), 250, 700).usable);
}

TEST(SimulateCli, NoiseFreeFrfIsTheExactModel) {
  eol::testing::TempDir dir;
  const CliRun r = Simulate({"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "z.csv",
                             "--noise-v", "0", "--noise-a", "0"});
  ASSERT_EQ(r.code, 0) << r.out;
  const analysis::Frf z = io::ReadFrfCsv(dir / "z.csv");
  EXPECT_FALSE(z.has_sigma());
  const analysis::FitSummary fit = Fit(z, 250, 700);
  ASSERT_TRUE(fit.usable) << fit.message;
  EXPECT_NEAR(fit.Find("f0_hz")->value, 390.0, 0.4);
}

TEST(SimulateCli, ErrorsNameTheOptionOrThePath) {
  eol::testing::TempDir dir;
  CliRun r = Simulate(
      {"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "z.csv", "--defect", "cracked"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("--defect: unknown defect 'cracked'"), std::string::npos) << r.out;

  std::ofstream(dir / "bad.json") << R"({"id": "x", "electrical": {"r_ohm": 0.5, "l_h": -1},
                                        "transducer": {"transmission_nm_per_a": 0.05}})";
  r = Simulate({"--motor", dir / "bad.json", "--out", dir / "z.csv"});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.out.find("/electrical/l_h: must be positive"), std::string::npos) << r.out;

  r = Simulate(
      {"--motor", kMotors + "pmsm-10pole.json", "--out", dir / "z.csv", "--format", "wav"});
  EXPECT_NE(r.code, 0);
}

}  // namespace
}  // namespace eol
