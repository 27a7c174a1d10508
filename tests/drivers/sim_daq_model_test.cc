// The simulated acquisition with either motor model (drivers/sim/sim_daq.h): both record the
// motor in the fixture through the bench circuit, so U/I on the excited lines is the motor's
// impedance; the time-domain model also shows the start transient. Config parsing names the
// offending field.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>

#include "analysis/fit/resonance_fit.h"
#include "analysis/signal/fft.h"
#include "analysis/signal/multisine.h"
#include "drivers/factory/factory.h"

namespace eol::drivers {
namespace {

using Cplx = std::complex<double>;

struct Measured {
  analysis::Recording rec;
  analysis::SimUnit unit;
  analysis::Excitation ex;
};

Measured Acquire(SimMotorModel model, std::size_t periods) {
  SimBenchSettings bench_settings;
  bench_settings.alive_timeout_ms = 0;  // no station here: the controller without the alive rule
  auto bench = std::make_shared<SimBench>(bench_settings);
  bench->LoadPart("SIM-DAQ-1");
  bench->Write(FixtureOutput::kExcitationEnable, true);
  SimDaqSettings settings;
  settings.model = model;
  settings.amplifier_output_ohm = 0.05;
  SimDaq daq(bench, settings);
  EXPECT_TRUE(daq.Connect().ok());
  Measured m;
  m.unit = *bench->part();
  m.ex = analysis::DesignMultisine(analysis::MultisineOptions{});
  AcquisitionRequest req;
  req.sample_rate_hz = m.ex.sample_rate_hz;
  req.period_samples = m.ex.period_samples;
  req.excitation_v = m.ex.Repeat(periods);
  std::atomic<bool> abort{false};
  auto rec = daq.Acquire(req, abort);
  EXPECT_TRUE(rec.ok()) << rec.status().message();
  m.rec = std::move(rec.value());
  return m;
}

// Z on the excited lines from the mean DFT of periods [first, last).
analysis::Frf LineImpedance(const Measured& m, std::size_t first, std::size_t last) {
  const std::size_t n = m.ex.period_samples;
  const analysis::RealFft fft(n);
  std::vector<Cplx> u(m.ex.lines.size()), i(m.ex.lines.size());
  for (std::size_t p = first; p < last; ++p) {
    const auto uk = fft.Forward(m.rec.voltage_v.data() + p * n);
    const auto ik = fft.Forward(m.rec.current_a.data() + p * n);
    for (std::size_t l = 0; l < m.ex.lines.size(); ++l) {
      u[l] += uk[m.ex.lines[l]];
      i[l] += ik[m.ex.lines[l]];
    }
  }
  analysis::Frf z;
  z.freq_hz = m.ex.LineFrequenciesHz();
  for (std::size_t l = 0; l < u.size(); ++l) z.value.push_back(u[l] / i[l]);
  return z;
}

class SimDaqModels : public ::testing::TestWithParam<SimMotorModel> {};

TEST_P(SimDaqModels, RecordsTheMotorInTheFixture) {
  const Measured m = Acquire(GetParam(), 5);
  const analysis::MotionalImpedance truth = m.unit.Electrical();
  analysis::ResonanceFitOptions o;
  o.f0_min_hz = 250;
  o.f0_max_hz = 700;
  const analysis::FitSummary fit = analysis::FitMotionalResonance(LineImpedance(m, 1, 5), o);
  ASSERT_TRUE(fit.usable) << fit.message;
  const analysis::FittedParameter* f0 = fit.Find("f0_hz");
  EXPECT_NEAR(f0->value, truth.f0_hz, 5 * f0->sigma + 0.05) << fit.message;
  EXPECT_NEAR(fit.Find("R_ohm")->value, truth.r_ohm, 0.01);
  EXPECT_NEAR(fit.chi2_per_dof, 1.0, 0.2);  // noise estimated from the residual
}

INSTANTIATE_TEST_SUITE_P(Model, SimDaqModels,
                         ::testing::Values(SimMotorModel::kSteadyState, SimMotorModel::kTimeDomain),
                         [](const auto& info) { return std::string(ToString(info.param)); });

TEST(SimDaq, TimeDomainShowsTheStartTransient) {
  const Measured td = Acquire(SimMotorModel::kTimeDomain, 2);
  const Measured ss = Acquire(SimMotorModel::kSteadyState, 2);
  const std::size_t n = td.ex.period_samples;
  double first = 0.0, second = 0.0;
  for (std::size_t t = 0; t < 200; ++t) {
    first = std::max(first, std::abs(td.rec.current_a[t] - ss.rec.current_a[t]));
    second = std::max(second, std::abs(td.rec.current_a[n + t] - ss.rec.current_a[n + t]));
  }
  EXPECT_GT(first, 0.05);   // the inductor starts from zero current
  EXPECT_LT(second, 0.01);  // one period later only the noise differs (1 mA rms per channel)
}

TEST(SimDaq, ConfigNamesTheModelField) {
  const nlohmann::json good = {
      {"driver", "sim"}, {"model", "time_domain"}, {"amplifier_output_ohm", 0.05}};
  const io::JsonObject daq(good, "/daq");
  EXPECT_EQ(daq.RequiredString("driver"), "sim");  // read by MakeDrivers before parsing
  const SimDaqSettings s = ParseSimDaqSettings(daq);
  EXPECT_EQ(s.model, SimMotorModel::kTimeDomain);
  EXPECT_DOUBLE_EQ(s.amplifier_output_ohm, 0.05);
  EXPECT_EQ(ParseSimDaqSettings(io::JsonObject(nlohmann::json::object(), "/daq")).model,
            SimMotorModel::kSteadyState);
  try {
    ParseSimDaqSettings(io::JsonObject(nlohmann::json{{"model", "spice"}}, "/daq"));
    FAIL() << "no error";
  } catch (const io::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("/daq/model: must be \"steady_state\" or"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace eol::drivers
