// The fit summary's field list (analysis/fit/fit_json.h): a real fit survives the round trip
// field by field, today's stored strings stay, and unknown terminations are refused by name.
#include "analysis/fit/fit_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <string>

#include "analysis/model/motor_model.h"

namespace eol::analysis {
namespace {

// The paper's case (analysis/README.md 2) with circular noise, sigma 0.02 ohm, fixed seed.
FitSummary ReferenceFit(bool with_sigma = true) {
  MotionalImpedance m;
  m.r_ohm = 0.5;
  m.l_h = 2e-3;
  m.rp_ohm = 0.5;
  m.f0_hz = 390.0;
  m.q = 50.0;
  std::vector<double> f;
  for (double x = 200.0; x <= 800.0; x += 2.0) f.push_back(x);
  Frf z = m.Evaluate(f);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 0.02 / std::sqrt(2.0));
  for (auto& v : z.value) v += std::complex<double>(n(rng), n(rng));
  if (with_sigma) z.sigma.assign(f.size(), 0.02);
  ResonanceFitOptions o;
  o.f0_min_hz = 250.0;
  o.f0_max_hz = 700.0;
  return FitMotionalResonance(z, o);
}

void ExpectRoundTrip(const FitSummary& s) {
  ASSERT_TRUE(s.usable) << s.message;
  ASSERT_EQ(s.covariance.rows(), 5);
  // Through text, as the store and the API carry it.
  const FitSummary back = nlohmann::json::parse(nlohmann::json(s).dump()).get<FitSummary>();
  EXPECT_EQ(back.model, s.model);
  EXPECT_EQ(back.usable, s.usable);
  EXPECT_EQ(back.message, s.message);
  EXPECT_EQ(back.termination, s.termination);
  ASSERT_EQ(back.params.size(), s.params.size());
  for (std::size_t i = 0; i < s.params.size(); ++i) {  // in the fit's order, not by name
    EXPECT_EQ(back.params[i].name, s.params[i].name);
    EXPECT_EQ(back.params[i].unit, s.params[i].unit);
    EXPECT_DOUBLE_EQ(back.params[i].value, s.params[i].value);
    EXPECT_DOUBLE_EQ(back.params[i].sigma, s.params[i].sigma);
  }
  ASSERT_EQ(back.covariance.rows(), s.covariance.rows());
  EXPECT_EQ((back.covariance - s.covariance).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_DOUBLE_EQ(back.chi2, s.chi2);
  EXPECT_EQ(back.dof, s.dof);
  EXPECT_DOUBLE_EQ(back.chi2_per_dof, s.chi2_per_dof);
  EXPECT_EQ(back.iterations, s.iterations);
  EXPECT_EQ(back.sigma_estimated, s.sigma_estimated);
  EXPECT_DOUBLE_EQ(back.estimated_sigma, s.estimated_sigma);
  // And the model the page draws is the same.
  EXPECT_DOUBLE_EQ(back.Model().f0_hz, s.Model().f0_hz);
}

TEST(FitJson, ARealFitSurvivesTheRoundTripFieldByField) {
  ExpectRoundTrip(ReferenceFit());
  // Without sigma the noise is estimated: sigma_estimated and estimated_sigma are set.
  const FitSummary estimated = ReferenceFit(false);
  ASSERT_TRUE(estimated.sigma_estimated);
  ASSERT_GT(estimated.estimated_sigma, 0.0);
  ExpectRoundTrip(estimated);
}

TEST(FitJson, KeepsTheStringsAndKeysThatRecordsAndThePageRead) {
  const nlohmann::json j = ReferenceFit();
  EXPECT_EQ(j.at("termination"), "converged");
  EXPECT_EQ(j.at("model"), "R+sL+parallel-RLC");
  EXPECT_TRUE(j.at("params").at("f0_hz").contains("sigma"));
  EXPECT_EQ(j.at("params").at("Q").at("unit"), "1");
  for (const char* key :
       {"usable", "message", "chi2", "dof", "chi2_per_dof", "iterations", "sigma_estimated"})
    EXPECT_TRUE(j.contains(key)) << key;
  for (Termination t : kAllTerminations) EXPECT_EQ(ParseTermination(ToString(t)), t);
  EXPECT_STREQ(ToString(Termination::kMaxIterations), "max_iterations");
  EXPECT_STREQ(ToString(Termination::kInvalidInput), "invalid_input");
}

TEST(FitJson, ReadsARecordWrittenBeforeTheCovarianceWasStored) {
  const nlohmann::json old = {
      {"model", "R+sL+parallel-RLC"},
      {"usable", true},
      {"termination", "failed"},
      {"message", "m"},
      {"chi2", 10.0},
      {"dof", 5},
      {"chi2_per_dof", 2.0},
      {"iterations", 3},
      {"sigma_estimated", true},
      {"params", {{"f0_hz", {{"value", 390.0}, {"sigma", nullptr}, {"unit", "Hz"}}}}}};
  const FitSummary s = old.get<FitSummary>();
  EXPECT_EQ(s.termination, Termination::kFailed);
  ASSERT_NE(s.Find("f0_hz"), nullptr);
  EXPECT_EQ(s.Find("f0_hz")->value, 390.0);
  EXPECT_TRUE(std::isnan(s.Find("f0_hz")->sigma));
  EXPECT_EQ(s.covariance.size(), 0);
}

TEST(FitJson, RefusesAnUnknownTerminationNamingTheFieldAndTheAcceptedValues) {
  nlohmann::json j = ReferenceFit();
  j["termination"] = "CONVERGENCE";
  try {
    (void)j.get<FitSummary>();
    FAIL() << "an unknown termination was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(),
                 "termination: unknown value 'CONVERGENCE' (accepted: converged, "
                 "max_iterations, failed, invalid_input)");
  }
}

}  // namespace
}  // namespace eol::analysis
