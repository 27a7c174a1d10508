// The paper's case end to end through the `eol` binary (analysis/README.md 2, the paper's section
// 4): the simulation clamps the shaft end rigidly (706 Hz), the real fixture rings at 390 Hz. `eol
// gap` must name fixture_compliance, estimate the fixture's stiffness, and predict where a rotor
// with poorly cemented magnets (706 -> 529 Hz in the simulation) rings in this real fixture (about
// 350 Hz: -10 % instead of -25 %).
//
// Two simulators stand for "the real motor": the population's single-mode clamped rotor
// (analysis/sim/population.h; its fixture is exactly a series spring, so the stiffness and the
// prediction are checked tightly against MotorPopulation) and the torsional chain of the
// motor JSON (recipes/motors; a clamp inertia and distributed springs, so the series-spring
// effect is only an approximation and the tolerances are wider: the chain itself puts the
// poorly cemented rotor at 366 Hz in the fixture).
#include <gtest/gtest.h>

#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>

#include "analysis/sim/measurement_sim.h"
#include "analysis/sim/population.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/json_config.h"
#include "drivers/io/motor_json.h"
#include "tests/support/child_process.h"

namespace eol {
namespace {

using testing::ChildProcess;
using testing::TempDir;

nlohmann::json RunGap(const std::vector<std::string>& args, const TempDir& dir, std::string* text) {
  std::vector<std::string> argv = {EOL_BINARY, "gap", "--json-out", dir / "out.json"};
  argv.insert(argv.end(), args.begin(), args.end());
  ChildProcess p(argv);
  const auto code = p.Wait(std::chrono::seconds(120));
  *text = p.output();
  EXPECT_EQ(code, 0) << p.output();
  std::ifstream in(dir / "out.json");
  return nlohmann::json::parse(in);
}

analysis::MotorPopulation Population() {
  analysis::MotorPopulation p;  // the paper's numbers, no production spread
  p.spread_inertia = p.spread_k_rotor = p.spread_k_fixture = p.spread_q = p.spread_r = p.spread_l =
      p.spread_transmission = 0.0;
  return p;
}

analysis::MotionalImpedance Motor(const analysis::MotorPopulation& p, bool defective,
                                  double k_fixture) {
  analysis::ClampedRotor r;
  r.inertia_kg_m2 = p.inertia_kg_m2;
  r.k_rotor_nm_per_rad = p.KRotorNmPerRad(defective);
  r.k_fixture_nm_per_rad = k_fixture;
  r.q = defective ? p.q_defect : p.q_good;
  r.transmission_nm_per_a = p.transmission_nm_per_a;
  return r.Electrical(p.r_ohm, p.l_h);
}

// The recipe's measurement through the simulator: multisine, steady state, DAQ noise, EIV.
analysis::Frf Measure(const analysis::ImpedanceFn& z, std::uint64_t seed) {
  const analysis::Excitation ex = analysis::DesignMultisine(analysis::MultisineOptions{});
  analysis::SimulatedMeasurementOptions o;
  o.seed = seed;
  const analysis::FrfSummary s = analysis::SimulateImpedanceMeasurement(z, ex, o);
  EXPECT_TRUE(s.usable) << s.message;
  return s.frf;
}

std::vector<double> Lines() {
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 1.0) f.push_back(x);
  return f;
}

TEST(GapPaperCase, ClampedRotorFixtureIsFoundAndTheDefectPredicted) {
  const analysis::MotorPopulation p = Population();
  const double rigid = std::numeric_limits<double>::infinity();
  TempDir dir;
  io::WriteFrfCsv(dir / "sim.csv", Motor(p, false, rigid).Evaluate(Lines()));
  io::WriteFrfCsv(dir / "sim-defect.csv", Motor(p, true, rigid).Evaluate(Lines()));
  const analysis::MotionalImpedance real = Motor(p, false, p.KFixtureNmPerRad());
  io::WriteFrfCsv(dir / "meas.csv", Measure([&](double f) { return real.At(f); }, 4));

  std::string text;
  // With the nominal calibrated within the design's tolerances (the default) the fixture is
  // named, and its stiffness and the prediction carry the rotor's own stiffness tolerance (15 %:
  // one measurement pins only the loaded f0, the fixture and the rotor spring share it): within
  // a few percent, and the prediction's sigma says so.
  const nlohmann::json c =
      RunGap({"--sim", dir / "sim.csv", "--measured", dir / "meas.csv", "--predict-sim",
              dir / "sim-defect.csv", "--inertia-kg-m2", "1e-4"},
             dir, &text);
  EXPECT_EQ(c["effect"], "fixture_compliance") << text;
  EXPECT_NEAR(c["params"]["k_fixture_nm_per_rad"].get<double>() / p.KFixtureNmPerRad(), 1.0, 0.05)
      << text;
  EXPECT_NEAR(c["prediction"]["f0_predicted_hz"].get<double>(), 350.5, 5.0) << text;
  EXPECT_LT(c["heldout"]["gap_after"].get<double>(), 1.3);
  // The exact simulation (the unit is the nominal plus the fixture): with the nominal kept at
  // the simulation's values the paper's figures hold to 1 %.
  const nlohmann::json j = RunGap({"--sim", dir / "sim.csv", "--measured", dir / "meas.csv",
                                   "--predict-sim", dir / "sim-defect.csv", "--inertia-kg-m2",
                                   "1e-4", "--plot", dir / "gap.svg", "--fixed-nominal"},
                                  dir, &text);
  EXPECT_EQ(j["effect"], "fixture_compliance") << text;
  // The simulation's calibration: 706 Hz.
  EXPECT_NEAR(j["calibration"]["params"]["f0_hz"]["value"].get<double>(), 706.0, 0.01);
  const double k = j["params"]["k_fixture_nm_per_rad"].get<double>();
  EXPECT_NEAR(k / p.KFixtureNmPerRad(), 1.0, 0.01) << "fixture " << k << " N m/rad";
  EXPECT_NEAR(j["params"]["f_loaded_hz"].get<double>(), 390.0, 0.5);
  EXPECT_GT(j["gap_before"].get<double>(), 10.0);
  EXPECT_LT(j["gap_after"].get<double>(), 1.2);
  EXPECT_EQ(j["heldout"]["method"], "interleaved-2fold");
  EXPECT_LT(j["heldout"]["gap_after"].get<double>(), 1.3);
  ASSERT_FALSE(j["where"].empty());
  // The most significant band holds the measured peak or the missing simulated one.
  const double lo = j["where"][0]["f_lo_hz"], hi = j["where"][0]["f_hi_hz"];
  EXPECT_TRUE((lo <= 390.0 && hi >= 390.0) || (lo <= 706.0 && hi >= 706.0)) << lo << "-" << hi;
  // Feature gap: the resonance moved down by ~316 Hz, far beyond its uncertainty.
  bool f0_feature = false;
  for (const auto& f : j["features"])
    if (f["name"] == "f0_hz") {
      f0_feature = true;
      EXPECT_NEAR(f["gap"].get<double>(), 390.0 - 706.0, 1.0);
      EXPECT_LT(f["significance"].get<double>(), -100.0);
    }
  EXPECT_TRUE(f0_feature);
  // Prediction: the poorly cemented rotor in this fixture.
  analysis::ClampedRotor defect;
  defect.inertia_kg_m2 = p.inertia_kg_m2;
  defect.k_rotor_nm_per_rad = p.KRotorNmPerRad(true);
  defect.k_fixture_nm_per_rad = p.KFixtureNmPerRad();
  const double truth = defect.NaturalFrequencyHz();  // about 350 Hz
  EXPECT_NEAR(truth, 350.0, 3.0);
  EXPECT_NEAR(j["prediction"]["f0_simulated_hz"].get<double>(), 529.0, 0.05);
  EXPECT_NEAR(j["prediction"]["f0_predicted_hz"].get<double>(), truth, 1.0) << text;
  EXPECT_LT(j["prediction"]["sigma_f0_hz"].get<double>(), 1.0);
  // The report and the plot.
  EXPECT_NE(text.find("WHICH        fixture_compliance"), std::string::npos) << text;
  EXPECT_NE(text.find("PREDICTION"), std::string::npos);
  std::ifstream svg(dir / "gap.svg");
  const std::string s((std::istreambuf_iterator<char>(svg)), std::istreambuf_iterator<char>());
  EXPECT_NE(s.find("<svg"), std::string::npos);
  EXPECT_NE(s.find("corrected"), std::string::npos);
}

TEST(GapPaperCase, TorsionalChainMotorJson) {
  const std::string motors = std::string(EOL_SOURCE_DIR) + "/recipes/motors/";
  TempDir dir;
  // The simulation: the chain with a rigid fixture (706 Hz); the defect: every bond poor.
  nlohmann::json defect = io::ReadJsonFile(motors + "pmsm-10pole-rigid.json");
  defect["rotor"]["soft_magnets"] = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9};
  std::ofstream(dir / "defect.json") << defect.dump(2);
  // "Reality": the same chain in the standard fixture (390 Hz), measured.
  const analysis::ClampedMotor real = io::LoadMotorJson(motors + "pmsm-10pole.json").Motor();
  io::WriteFrfCsv(dir / "meas.csv", Measure([&](double f) { return real.Impedance(f); }, 9));
  std::string text;
  const nlohmann::json j = RunGap({"--sim", motors + "pmsm-10pole-rigid.json", "--measured",
                                   dir / "meas.csv", "--predict-sim", dir / "defect.json"},
                                  dir, &text);
  const std::string effect = j["effect"];
  EXPECT_NE(effect.find("fixture_compliance"), std::string::npos) << text;
  EXPECT_LT(j["heldout"]["gap_after"].get<double>(),
            j["heldout"]["gap_before"].get<double>() / 5.0);
  // The chain's fixture is 887.9 N m/rad behind a clamp inertia; the series-spring estimate
  // with the rotor's inertia (1e-4 kg m^2) lands on the population's 864 N m/rad.
  const double k = j["params"]["k_fixture_nm_per_rad"].get<double>();
  EXPECT_NEAR(k / analysis::MotorPopulation{}.KFixtureNmPerRad(), 1.0, 0.05) << k;
  EXPECT_NEAR(j["calibration"]["inertia_kg_m2"].get<double>(), 1e-4, 1e-9);
  EXPECT_EQ(j["calibration"]["inertia_source"], "simulation");
  // The chain puts the poorly cemented rotor at 366 Hz in the fixture, the series spring at
  // about 350: the prediction must land in that neighbourhood, far from the naive 529 * 390/706.
  const double f_pred = j["prediction"]["f0_predicted_hz"].get<double>();
  EXPECT_GT(f_pred, 340.0) << text;
  EXPECT_LT(f_pred, 375.0) << text;
}

}  // namespace
}  // namespace eol
