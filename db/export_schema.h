// The export schema for quality engineering: one row per test, in fixed columns that never
// depend on the data exported (`eol export`, CSV and JSON). One field list, here, serves the
// CSV header, the CSV cells, the JSON objects and the documented table (`eol export --schema`,
// deploy/OPERATIONS.md "Export schema"), so the three cannot drift apart.
//
// Row layout (schema version kExportSchemaVersion):
//   1. the base columns (kind of test, identity, times, outcome, first reason, recipe, who,
//      order and the key conditions), always the same, in the same order; a test's own
//      columns (identity to order) are the exported entries of the one column list that the
//      store and the central record share (db/test_columns.h), the key conditions are here;
//   2. for each declared measurement name N, in the order declared, six columns
//      N_value, N_sigma, N_lo, N_hi, N_unit, N_outcome.
// The declared list is the standard names (analysis/qc/measurement_names.h) followed by what
// the recipes the caller names declare (limits, masks, further phase pairs); it is never
// taken from the records, so two databases export the same header. A test without a declared
// measurement has empty cells (JSON null) there; a record's measurement that is not declared
// has no column (ExportUndeclared lists such names so the caller can say so).
//
// Stability promise: a column, once in a schema version, keeps its name, type, unit and
// meaning, and its position for the same declared list; a later version only adds columns
// after the last one (and raises kExportSchemaVersion). Nothing is renamed or removed.
#pragma once

#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>
#include <vector>

#include "db/test_record.h"

namespace eol::db {

// Version 2 (issue 12) appended the standard measurement motional_residue_ohm_per_s after
// fit_chi2_per_dof; version 1 files have the same columns up to there. Version 3 appended
// bond_index_pct (analysis/qc/bond_index.h) after it, version 4 second_mode_chi2_drop,
// version 5 resonance_f_ref_pressure_hz (analysis/qc/f0_pressure.h).
inline constexpr int kExportSchemaVersion = 5;

enum class ExportType { kInteger, kNumber, kText, kTime, kBool };
const char* ToString(ExportType t);  // "integer", "number", "text", "time", "bool"

// One cell: empty (CSV "", JSON null), an integer, a number, text or a boolean.
using ExportValue = std::variant<std::monostate, std::int64_t, double, std::string, bool>;

struct ExportColumn {
  // CSV header name: `key` for a base column, "<measurement>_<key>" for a measurement's.
  std::string name;
  // The JSON place: top-level `key`, or measurements.<measurement>.<key>.
  std::string measurement;  // empty for a base column
  std::string key;
  ExportType type = ExportType::kText;
  std::string unit;  // of the value; "" for text, "(N_unit)" when the row's unit column says
  std::string meaning;
  std::function<ExportValue(const TestRecord&)> get;
};

// The standard names followed by `extra` (in order), each name once.
std::vector<std::string> ExportMeasurementNames(const std::vector<std::string>& extra);

// Every column for the declared measurement names, in row order.
std::vector<ExportColumn> ExportColumns(const std::vector<std::string>& measurement_names);

// The CSV header line and one row (RFC 4180: a field with a comma, quote, CR or LF is quoted,
// quotes doubled; lines end with "\n"). Numbers are written in the shortest form that reads
// back to the same double; booleans as true/false.
std::string ExportCsvHeader(const std::vector<ExportColumn>& columns);
std::string ExportCsvRow(const std::vector<ExportColumn>& columns, const TestRecord& record);

// The row as a JSON object, keys in column order: base columns as top-level keys, measurement
// columns as
// {"measurements": {"<name>": {"value", "sigma", "lo", "hi", "unit", "outcome"}}}; every
// declared measurement is present (its fields null when the test lacks it).
nlohmann::ordered_json ExportJsonRow(const std::vector<ExportColumn>& columns,
                                     const TestRecord& record);

// The schema as a Markdown table: | column | type | unit | meaning |.
std::string ExportSchemaMarkdown(const std::vector<ExportColumn>& columns);

// Names of the record's measurements that have no column in `columns`.
std::vector<std::string> ExportUndeclared(const std::vector<ExportColumn>& columns,
                                          const TestRecord& record);

}  // namespace eol::db
