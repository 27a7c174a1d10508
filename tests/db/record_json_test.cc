// The record's kind (db/test_record.h RecordKind): stored strings, JSON round trip, refusal of
// an unknown kind by field name.
#include <gtest/gtest.h>

#include <stdexcept>

#include "db/test_record.h"

namespace eol::db {
namespace {

TEST(RecordKind, KeepsTheStringsTheSchemaChecks) {
  EXPECT_STREQ(ToString(RecordKind::kProduction), "production");
  EXPECT_STREQ(ToString(RecordKind::kSelfCheck), "self_check");
  for (RecordKind k : kAllRecordKinds) EXPECT_EQ(ParseRecordKind(ToString(k)), k);
}

TEST(RecordKind, RoundTripsInTheRecordAndDefaultsToProductionForOldRecords) {
  TestRecord r;
  r.serial = "U-1";
  r.recipe_id = "rec";
  r.outcome = analysis::Outcome::kPass;
  r.kind = RecordKind::kSelfCheck;
  nlohmann::json j = r;
  EXPECT_EQ(j.at("kind"), "self_check");
  EXPECT_EQ(j.get<TestRecord>().kind, RecordKind::kSelfCheck);
  j.erase("kind");  // written before schema v3
  EXPECT_EQ(j.get<TestRecord>().kind, RecordKind::kProduction);
}

TEST(RecordKind, RefusesAnUnknownKindNamingTheFieldAndTheAcceptedValues) {
  TestRecord r;
  r.serial = "U-1";
  r.recipe_id = "rec";
  nlohmann::json j = r;
  j["kind"] = "calibration";
  try {
    (void)j.get<TestRecord>();
    FAIL() << "kind 'calibration' was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "kind: unknown value 'calibration' (accepted: production, self_check)");
  }
}

}  // namespace
}  // namespace eol::db
