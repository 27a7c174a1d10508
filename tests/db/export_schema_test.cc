// db/export_schema.h: fixed columns whatever the data, one field list for CSV and JSON.
#include "db/export_schema.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

namespace eol::db {
namespace {

TestRecord Pass() {
  TestRecord r;
  r.id = 7;
  r.serial = "SN-1";
  r.station_id = "eol-1";
  r.started_at = "2026-11-20T08:00:00.000Z";
  r.finished_at = "2026-11-20T08:00:05.250Z";
  r.outcome = analysis::Outcome::kPass;
  r.recipe_id = "pmsm-10pole";
  r.recipe_version = 3;
  r.recipe_hash = std::string(64, 'b');
  TestConditions& c = r.conditions;
  c.clamp_pressure_bar = 5.25;
  c.phase_pair = 0;
  c.excitation_v_rms = 1.3;
  c.excitation_a_rms = std::nan("");  // stored as null
  c.winding_temperature_c = 23.5;
  c.conditions_in_window = true;
  c.simulation = "simulated fixture";
  analysis::Measurement m;
  m.name = "resonance_f_hz";
  m.unit = "Hz";
  m.value = 391.123456789012;
  m.sigma = 0.0421;
  m.limit.lo = 370;
  m.limit.hi = 420;
  m.outcome = analysis::MeasurementOutcome::kPass;
  r.measurements.push_back(m);
  return r;
}

std::vector<std::string> SplitHeader(const std::string& h) {
  std::vector<std::string> names;
  std::string cur;
  for (char c : h) {
    if (c == ',' || c == '\n') {
      names.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  return names;
}

TEST(ExportSchema, BaseColumnsComeFirstInTheDocumentedOrder) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  const std::vector<std::string> names = SplitHeader(ExportCsvHeader(columns));
  const std::vector<std::string> base = {"schema_version",
                                         "id",
                                         "serial",
                                         "station_id",
                                         "started_at",
                                         "finished_at",
                                         "outcome",
                                         "reason_code",
                                         "reason_text",
                                         "reason_count",
                                         "kind",
                                         "recipe_id",
                                         "recipe_version",
                                         "recipe_hash",
                                         "software_version",
                                         "retest_of",
                                         "operator_id",
                                         "shift",
                                         "order_number",
                                         "winding_temperature_c",
                                         "clamp_pressure_bar",
                                         "excitation_v_rms",
                                         "excitation_a_rms",
                                         "phase_pair",
                                         "conditions_in_window",
                                         "simulated",
                                         "simulation"};
  ASSERT_GE(names.size(), base.size());
  // Schema version 1: these names at these positions, forever (append only).
  for (std::size_t i = 0; i < base.size(); ++i) EXPECT_EQ(names[i], base[i]) << "column " << i;
  EXPECT_EQ(names[base.size()], "resonance_f_hz_value");
  const std::vector<std::string> fields = {"value", "sigma", "lo", "hi", "unit", "outcome"};
  EXPECT_EQ(names.size(), base.size() + 10 * 6) << "ten standard measurements, six fields each";
  for (std::size_t k = 0; k < fields.size(); ++k)
    EXPECT_EQ(names[base.size() + 6 + k], "resonance_q_" + fields[k]);
}

TEST(ExportSchema, RecipeNamesFollowTheStandardOnesOnce) {
  const auto names = ExportMeasurementNames({"resonance_q", "mask_low_lines_outside"});
  ASSERT_EQ(names.size(), 11u);
  EXPECT_EQ(names[1], "resonance_q");
  EXPECT_EQ(names[6], "motional_residue_ohm_per_s");   // appended in schema version 2
  EXPECT_EQ(names[7], "bond_index_pct");               // appended in schema version 3
  EXPECT_EQ(names[8], "second_mode_chi2_drop");        // appended in schema version 4
  EXPECT_EQ(names[9], "resonance_f_ref_pressure_hz");  // appended in schema version 5
  EXPECT_EQ(names[10], "mask_low_lines_outside");
  EXPECT_THROW(ExportColumns({"a", "a"}), std::invalid_argument);
}

TEST(ExportSchema, HeaderDoesNotDependOnTheRecords) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  TestRecord empty;  // an ERROR with no measurement at all
  empty.reasons.push_back({analysis::ReasonCode::kFixture, "no answer"});
  const std::string a = ExportCsvRow(columns, empty);
  const std::string b = ExportCsvRow(columns, Pass());
  // The same number of cells (no text field here holds a comma).
  EXPECT_EQ(std::count(a.begin(), a.end(), ','), std::count(b.begin(), b.end(), ','));
  EXPECT_EQ(std::count(a.begin(), a.end(), ','), static_cast<long>(columns.size()) - 1);
}

TEST(ExportSchema, CsvCellsCarryValueLimitsUnitAndOutcome) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  const std::vector<std::string> head = SplitHeader(ExportCsvHeader(columns));
  const std::vector<std::string> row = SplitHeader(ExportCsvRow(columns, Pass()));
  ASSERT_EQ(row.size(), head.size());
  auto cell = [&](const std::string& name) {
    for (std::size_t i = 0; i < head.size(); ++i)
      if (head[i] == name) return row[i];
    ADD_FAILURE() << "no column " << name;
    return std::string();
  };
  EXPECT_EQ(cell("schema_version"), std::to_string(kExportSchemaVersion));
  EXPECT_EQ(cell("id"), "7");
  EXPECT_EQ(cell("outcome"), "PASS");
  EXPECT_EQ(cell("reason_code"), "");
  EXPECT_EQ(cell("kind"), "production");
  EXPECT_EQ(cell("clamp_pressure_bar"), "5.25");
  EXPECT_EQ(cell("phase_pair"), "0");
  EXPECT_EQ(cell("excitation_a_rms"), "") << "null condition";
  EXPECT_EQ(cell("conditions_in_window"), "true");
  EXPECT_EQ(cell("simulated"), "true");
  EXPECT_EQ(cell("resonance_f_hz_lo"), "370");
  EXPECT_EQ(cell("resonance_f_hz_hi"), "420");
  EXPECT_EQ(cell("resonance_f_hz_unit"), "Hz");
  EXPECT_EQ(cell("resonance_f_hz_outcome"), "PASS");
  EXPECT_EQ(cell("resonance_q_value"), "") << "a measurement the test lacks is empty";
  // The value reads back to the very same double.
  const std::string v = cell("resonance_f_hz_value");
  double back = 0.0;
  std::from_chars(v.data(), v.data() + v.size(), back);
  EXPECT_EQ(back, 391.123456789012) << v;
}

TEST(ExportSchema, JsonRowHasTheSameFieldsAsTheCsv) {
  const auto columns = ExportColumns(ExportMeasurementNames({"mask_x_lines_outside"}));
  const auto j = ExportJsonRow(columns, Pass());
  std::size_t fields = 0;
  for (const auto& [key, value] : j.items()) {
    if (key != "measurements") ++fields;
  }
  ASSERT_EQ(j["measurements"].size(), 11u);
  for (const auto& [name, m] : j["measurements"].items()) fields += m.size();
  EXPECT_EQ(fields, columns.size());
  EXPECT_EQ(j["serial"], "SN-1");
  EXPECT_EQ(j["measurements"]["resonance_f_hz"]["value"].get<double>(), 391.123456789012);
  EXPECT_EQ(j["measurements"]["resonance_f_hz"]["hi"], 420.0);
  EXPECT_EQ(j["measurements"]["resonance_f_hz"]["outcome"], "PASS");
  EXPECT_TRUE(j["measurements"]["mask_x_lines_outside"]["value"].is_null());
  EXPECT_TRUE(j["retest_of"].is_null());
  EXPECT_EQ(j.begin().key(), "schema_version") << "keys in column order";
}

TEST(ExportSchema, CsvQuotesTextWithCommasQuotesAndNewlines) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  TestRecord r = Pass();
  r.work.order_number = "PO-9, \"rush\"\nline 2";
  const std::string row = ExportCsvRow(columns, r);
  EXPECT_NE(row.find(",\"PO-9, \"\"rush\"\"\nline 2\","), std::string::npos) << row;
}

TEST(ExportSchema, MarkdownTableHasOneLinePerColumn) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  const std::string md = ExportSchemaMarkdown(columns);
  EXPECT_EQ(static_cast<std::size_t>(std::count(md.begin(), md.end(), '\n')), columns.size() + 2);
  EXPECT_NE(md.find("| `clamp_pressure_bar` | number | bar |"), std::string::npos) << md;
}

TEST(ExportSchema, UndeclaredMeasurementsAreNamed) {
  const auto columns = ExportColumns(ExportMeasurementNames({}));
  TestRecord r = Pass();
  r.measurements.push_back({});
  r.measurements.back().name = "mask_y_lines_outside";
  EXPECT_EQ(ExportUndeclared(columns, r), std::vector<std::string>{"mask_y_lines_outside"});
}

}  // namespace
}  // namespace eol::db
