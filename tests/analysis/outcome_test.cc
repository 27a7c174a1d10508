// Outcome severity (analysis::Worse) and reason codes (analysis/qc/measurement.h): the order
// ABORTED > ERROR > FAIL > PASS over every pair, both ways round, and the codes' stable names.
#include <gtest/gtest.h>

#include <cmath>

#include "analysis/qc/measurement.h"

namespace eol::analysis {
namespace {

TEST(Worse, OrdersAbortedOverErrorOverFailOverPassBothWaysRound) {
  const Outcome by_severity[] = {Outcome::kPass, Outcome::kFail, Outcome::kError,
                                 Outcome::kAborted};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      EXPECT_EQ(Worse(by_severity[i], by_severity[j]), by_severity[std::max(i, j)])
          << ToString(by_severity[i]) << " vs " << ToString(by_severity[j]);
  // The case the station meets: one phase pair FAILs, another could not be measured.
  EXPECT_EQ(Worse(Outcome::kFail, Outcome::kError), Outcome::kError);
}

TEST(ReasonCode, NamesAreStableSnakeCaseAndParseBack) {
  const std::pair<ReasonCode, const char*> names[] = {{ReasonCode::kLimit, "limit"},
                                                      {ReasonCode::kMask, "mask"},
                                                      {ReasonCode::kCondition, "condition"},
                                                      {ReasonCode::kInterlock, "interlock"},
                                                      {ReasonCode::kFixture, "fixture"},
                                                      {ReasonCode::kAcquisition, "acquisition"},
                                                      {ReasonCode::kAnalysis, "analysis"},
                                                      {ReasonCode::kAborted, "aborted"},
                                                      {ReasonCode::kStore, "store"},
                                                      {ReasonCode::kLockout, "lockout"},
                                                      {ReasonCode::kRetestLimit, "retest_limit"},
                                                      {ReasonCode::kSelfCheck, "self_check"},
                                                      {ReasonCode::kInternal, "internal"},
                                                      {ReasonCode::kLegacy, "legacy"},
                                                      {ReasonCode::kClipped, "clipped"}};
  for (const auto& [code, name] : names) {
    EXPECT_STREQ(ToString(code), name);
    EXPECT_EQ(ParseReasonCode(name), code) << name;
  }
  EXPECT_FALSE(ParseReasonCode("Limit").has_value());
}

TEST(Judge, CodesOutOfLimitsAndMissingValues) {
  const std::vector<MeasurementSpec> specs = {{"resonance_f_hz", "Hz", "", {370.0, 420.0, 0.0}},
                                              {"quality_q", "", "", {10.0, std::nullopt, 0.0}}};
  Verdict v = Judge(specs, {{"resonance_f_hz", {352.0, 0.1}}, {"quality_q", {50.0, 1.0}}});
  EXPECT_EQ(v.outcome, Outcome::kFail);
  ASSERT_EQ(v.reasons.size(), 1u);
  EXPECT_EQ(v.reasons[0].code, ReasonCode::kLimit);
  EXPECT_EQ(v.reasons[0].text, "resonance_f_hz = 352 Hz below lower limit 370");
  v = Judge(specs, {{"resonance_f_hz", {352.0, 0.1}}, {"quality_q", {50.0, 1.0}}},
            ReasonCode::kMask);
  EXPECT_EQ(v.reasons[0].code, ReasonCode::kMask);
  v = Judge(specs, {{"resonance_f_hz", {std::nan(""), 0.1}}, {"quality_q", {5.0, 1.0}}});
  EXPECT_EQ(v.outcome, Outcome::kError);
  ASSERT_EQ(v.reasons.size(), 2u);
  EXPECT_EQ(v.reasons[0], (Reason{ReasonCode::kAnalysis, "resonance_f_hz: not measured"}));
  EXPECT_EQ(v.reasons[1].code, ReasonCode::kLimit);
}

}  // namespace
}  // namespace eol::analysis
