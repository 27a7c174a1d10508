// The record's conditions (db/test_conditions.h): every field to the JSON keys the station has
// always written and back, absent fields absent, and an old or foreign record's keys (unknown,
// null, of another type) kept through a read and write, never throwing.
#include "db/test_conditions.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "db/test_record.h"

namespace eol::db {
namespace {

using nlohmann::json;

TestConditions EveryField() {
  TestConditions c;
  c.clamp_pressure_bar = 5.1;
  c.phase_pair = 1;
  c.excitation_peak_v = 2.0;
  c.crest_factor = 1.6;
  c.line_spacing_hz = 10.0;
  c.sample_rate_hz = 8000.0;
  c.clamp_pressure_min_bar = 5.05;
  c.clamp_pressure_max_bar = 5.15;
  c.watchdog_max_gap_ms = 12.5;
  c.analysis_overlapped_s = 0.25;
  c.periods_used = 8;
  c.looks[""] = {2, std::vector<std::string>{"resonance_f_hz"}};
  c.looks["@V-W"] = {1, std::nullopt};
  c.excitation_v_rms = 1.3;
  c.excitation_a_rms = 0.4;
  c.winding_temperature_c = 24.25;
  c.conditions_in_window = true;
  c.simulation = "fixture driver 'sim', daq driver 'sim'";
  c.variant = "P8H";
  c.variant_by = "prefix 'P8H-'";
  return c;
}

// The keys and values of the records before the typed conditions, written out by hand.
const json kEveryFieldJson = json::parse(R"({
  "clamp_pressure_bar": 5.1, "phase_pair": 1, "excitation_peak_v": 2.0, "crest_factor": 1.6,
  "line_spacing_hz": 10.0, "sample_rate_hz": 8000.0, "clamp_pressure_min_bar": 5.05,
  "clamp_pressure_max_bar": 5.15, "watchdog_max_gap_ms": 12.5, "analysis_overlapped_s": 0.25,
  "periods_used": 8, "looks": 2, "undecided": ["resonance_f_hz"], "looks@V-W": 1,
  "excitation_v_rms": 1.3, "excitation_a_rms": 0.4, "winding_temperature_c": 24.25,
  "conditions_in_window": true, "simulation": "fixture driver 'sim', daq driver 'sim'",
  "variant": "P8H", "variant_by": "prefix 'P8H-'"})");

TEST(TestConditions, WritesEveryFieldUnderItsKeyAndReadsItBack) {
  const json j = EveryField();
  EXPECT_EQ(j, kEveryFieldJson) << j.dump();
  EXPECT_EQ(j.dump(), kEveryFieldJson.dump());  // the same bytes as the JSON bag wrote
  const TestConditions back = kEveryFieldJson.get<TestConditions>();
  EXPECT_EQ(back, EveryField());
  EXPECT_TRUE(back.extra.empty()) << back.extra.dump();
}

TEST(TestConditions, LeavesUnsetFieldsAbsent) {
  EXPECT_EQ(json(TestConditions{}), json::object());
  TestConditions c;
  c.clamp_pressure_bar = 4.9;
  c.phase_pair = 0;
  EXPECT_EQ(json(c), json::parse(R"({"clamp_pressure_bar": 4.9, "phase_pair": 0})"));
  const TestConditions back = json(c).get<TestConditions>();
  EXPECT_EQ(back, c);
  EXPECT_FALSE(back.excitation_v_rms.has_value());
  EXPECT_TRUE(back.looks.empty());
}

TEST(TestConditions, WritesANonFiniteValueAsNullAndReadsNullAsUnsetButKept) {
  TestConditions c;
  c.excitation_v_rms = std::nan("");
  c.excitation_a_rms = std::numeric_limits<double>::infinity();
  const json j = c;
  EXPECT_EQ(j.dump(), R"({"excitation_a_rms":null,"excitation_v_rms":null})");
  const TestConditions back = j.get<TestConditions>();
  EXPECT_FALSE(back.excitation_v_rms.has_value());  // as the JSON readers' is_number() saw it
  EXPECT_EQ(json(back), j);                         // the key is not lost
}

TEST(TestConditions, KeepsAnOldRecordsUnknownAndMistypedKeysThroughARoundTrip) {
  const json old = json::parse(R"({
    "clamp_pressure_bar": 5, "phase_pair": "U-V", "periods_used": -3, "looks": 1.5,
    "looks@W-U": 3, "undecided@W-U": ["f0", 7], "looksie": 2, "humidity_pct": 41.5,
    "operator_note": {"text": "re-seated"}})");
  TestConditions c;
  ASSERT_NO_THROW(c = old.get<TestConditions>());
  EXPECT_EQ(c.clamp_pressure_bar, 5.0);  // an integer is a number of bar all the same
  EXPECT_FALSE(c.phase_pair.has_value());
  EXPECT_FALSE(c.periods_used.has_value());
  ASSERT_EQ(c.looks.size(), 1u);
  EXPECT_EQ(c.looks.at("@W-U").looks, 3);
  EXPECT_FALSE(c.looks.at("@W-U").undecided.has_value());
  EXPECT_EQ(c.extra, json::parse(R"({"phase_pair": "U-V", "periods_used": -3, "looks": 1.5,
    "undecided@W-U": ["f0", 7], "looksie": 2, "humidity_pct": 41.5,
    "operator_note": {"text": "re-seated"}})"));
  EXPECT_EQ(json(c), old);  // written again: every key, every value as it was read
}

TEST(TestConditions, AFieldSetAfterReadingWinsOverTheKeptKey) {
  auto c = json::parse(R"({"watchdog_max_gap_ms": null, "note": "x"})").get<TestConditions>();
  c.watchdog_max_gap_ms = 7.5;
  EXPECT_EQ(json(c), json::parse(R"({"watchdog_max_gap_ms": 7.5, "note": "x"})"));
}

TEST(TestConditions, ReadsNullAsNoneAndRefusesANonObjectNamingTheField) {
  EXPECT_EQ(json(nullptr).get<TestConditions>(), TestConditions{});
  try {
    (void)json::array({1}).get<TestConditions>();
    FAIL() << "an array was accepted as conditions";
  } catch (const json::type_error& e) {
    EXPECT_NE(std::string(e.what()).find("conditions: must be an object, not array"),
              std::string::npos)
        << e.what();
  }
}

TEST(TestConditions, RoundTripInTheRecordAndAbsentInAnOldOne) {
  TestRecord r;
  r.serial = "U-1";
  r.recipe_id = "rec";
  r.conditions = EveryField();
  json j = r;
  EXPECT_EQ(j.at("conditions"), kEveryFieldJson);
  EXPECT_EQ(j.get<TestRecord>().conditions, EveryField());
  j.erase("conditions");
  EXPECT_EQ(j.get<TestRecord>().conditions, TestConditions{});
}

}  // namespace
}  // namespace eol::db
