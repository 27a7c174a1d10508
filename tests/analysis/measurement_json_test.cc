// Measurement and verdict field lists (analysis/qc/measurement_json.h): round trips through
// text, the stored strings, and refusal of unknown outcomes by field name.
#include "analysis/qc/measurement_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace eol::analysis {
namespace {

Verdict SampleVerdict() {
  // Judged, not hand-built: one pass with an open side, one fail, one value not measured.
  const std::vector<MeasurementSpec> specs = {
      {"resonance_f_hz", "Hz", "f0", {370.0, 420.0, 3.0}},
      {"resonance_q", "", "Q", {std::nullopt, 40.0, 0.0}},
      {"winding_r_ohm", "ohm", "R", {0.4, std::nullopt, 0.0}}};
  const std::map<std::string, Estimate> values = {
      {"resonance_f_hz", {390.25, 0.04}},
      {"resonance_q", {51.0, 1.5}},
      {"winding_r_ohm", {std::numeric_limits<double>::quiet_NaN(), 0.001}}};
  return Judge(specs, values);
}

TEST(MeasurementJson, AJudgedVerdictSurvivesTheRoundTrip) {
  const Verdict v = SampleVerdict();
  ASSERT_EQ(v.measurements.size(), 3u);
  const nlohmann::json j = nlohmann::json::parse(nlohmann::json(v).dump());
  const Verdict back = j.get<Verdict>();
  EXPECT_EQ(back.outcome, v.outcome);
  EXPECT_EQ(back.reasons, v.reasons);
  ASSERT_EQ(back.measurements.size(), v.measurements.size());
  for (std::size_t i = 0; i < v.measurements.size(); ++i) {
    const Measurement& a = v.measurements[i];
    const Measurement& b = back.measurements[i];
    EXPECT_EQ(b.name, a.name);
    EXPECT_EQ(b.unit, a.unit);
    EXPECT_EQ(b.doc, a.doc);
    EXPECT_TRUE(b.value == a.value || (std::isnan(a.value) && std::isnan(b.value))) << a.name;
    EXPECT_TRUE(b.sigma == a.sigma || (std::isnan(a.sigma) && std::isnan(b.sigma))) << a.name;
    EXPECT_EQ(b.limit.lo, a.limit.lo);
    EXPECT_EQ(b.limit.hi, a.limit.hi);
    EXPECT_EQ(b.limit.marginal, a.limit.marginal);
    EXPECT_EQ(b.outcome, a.outcome) << a.name;
    EXPECT_EQ(b.marginal, a.marginal);
  }
}

TEST(MeasurementJson, KeepsTheStoredStrings) {
  const nlohmann::json j = SampleVerdict();
  EXPECT_EQ(j.at("outcome"), "ERROR");  // a measurement was missing
  EXPECT_EQ(j.at("measurements").at(0).at("outcome"), "PASS");
  EXPECT_EQ(j.at("measurements").at(1).at("outcome"), "FAIL");
  EXPECT_TRUE(j.at("measurements").at(1).at("limit").at("lo").is_null());
  EXPECT_TRUE(j.at("measurements").at(2).at("value").is_null());  // NaN is null
  for (Outcome o : kAllOutcomes) EXPECT_EQ(nlohmann::json(o).get<Outcome>(), o);
  for (MeasurementOutcome o : kAllMeasurementOutcomes)
    EXPECT_EQ(nlohmann::json(o).get<MeasurementOutcome>(), o);
}

template <class T>
std::string RefusalOf(const nlohmann::json& j) {
  try {
    (void)j.get<T>();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "accepted";
}

TEST(MeasurementJson, RefusesUnknownOutcomesNamingTheFieldAndTheAcceptedValues) {
  nlohmann::json v = SampleVerdict();
  v["outcome"] = "pass";
  EXPECT_EQ(RefusalOf<Verdict>(v),
            "outcome: unknown value 'pass' (accepted: PASS, FAIL, ERROR, ABORTED)");
  nlohmann::json m = SampleVerdict().measurements.at(0);
  m["outcome"] = "MARGINAL";
  EXPECT_EQ(RefusalOf<Measurement>(m),
            "measurement outcome: unknown value 'MARGINAL' (accepted: PASS, FAIL, UNSET)");
}

}  // namespace
}  // namespace eol::analysis
