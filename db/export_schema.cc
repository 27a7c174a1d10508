#include "db/export_schema.h"

#include <charconv>
#include <cmath>
#include <set>
#include <stdexcept>
#include <type_traits>

#include "analysis/qc/measurement_names.h"
#include "db/test_columns.h"

namespace eol::db {
namespace {

using Get = std::function<ExportValue(const TestRecord&)>;

ExportValue Text(const std::string& s) { return s; }

ExportValue Number(double v) {
  if (!std::isfinite(v)) return std::monostate{};
  return v;
}

// A numeric condition of the record (db/test_conditions.h); empty when unset or not finite.
template <class T>
Get Condition(std::optional<T> TestConditions::*field) {
  return [field](const TestRecord& r) -> ExportValue {
    const std::optional<T>& v = r.conditions.*field;
    if (!v) return std::monostate{};
    if constexpr (std::is_integral_v<T>) return static_cast<std::int64_t>(*v);
    return Number(*v);
  };
}

ExportColumn Base(const char* key, ExportType type, const char* unit, const char* meaning,
                  Get get) {
  return {key, "", key, type, unit, meaning, std::move(get)};
}

ExportValue ToExport(const ColumnValue& v, const char* name) {
  if (const auto* i = std::get_if<std::int64_t>(&v)) return *i;
  if (const auto* t = std::get_if<std::string>(&v)) return *t;
  if (std::holds_alternative<nlohmann::json>(v))
    throw std::logic_error(std::string("export: test column ") + name + " is JSON");
  return std::monostate{};
}

// The exported test columns (db/test_columns.h) whose export_since passes `pick`, in order.
template <typename Pick>
void AddTestColumns(std::vector<ExportColumn>& c, Pick pick) {
  for (const TestColumn& t : TestColumns()) {
    if (t.export_since == 0 || !pick(t.export_since)) continue;
    c.push_back(
        Base(t.name, t.export_type, t.unit, t.doc,
             [get = t.get, name = t.name](const TestRecord& r) { return ToExport(get(r), name); }));
  }
}

// The base columns, in row order: the schema version, the test columns of version 1
// (db/test_columns.h), the key conditions, then test columns added in later versions. Append
// only (export_schema.h).
static_assert(kExportSchemaVersion == 5, "say the new version in schema_version's meaning");

std::vector<ExportColumn> BaseColumns() {
  using T = ExportType;
  std::vector<ExportColumn> c;
  c.push_back(
      Base("schema_version", T::kInteger, "", "Version of this export schema (5)",
           [](const TestRecord&) -> ExportValue { return std::int64_t{kExportSchemaVersion}; }));
  AddTestColumns(c, [](int since) { return since == 1; });
  c.push_back(Base("winding_temperature_c", T::kNumber, "degC",
                   "Winding temperature estimated from the fitted resistance",
                   Condition(&TestConditions::winding_temperature_c)));
  c.push_back(Base("clamp_pressure_bar", T::kNumber, "bar", "Clamp pressure read before exciting",
                   Condition(&TestConditions::clamp_pressure_bar)));
  c.push_back(Base("excitation_v_rms", T::kNumber, "V", "Excitation voltage, rms",
                   Condition(&TestConditions::excitation_v_rms)));
  c.push_back(Base("excitation_a_rms", T::kNumber, "A", "Excitation current, rms",
                   Condition(&TestConditions::excitation_a_rms)));
  c.push_back(Base("phase_pair", T::kInteger, "", "First phase pair excited: 0 U-V, 1 V-W, 2 W-U",
                   Condition(&TestConditions::phase_pair)));
  c.push_back(Base("conditions_in_window", T::kBool, "",
                   "Every judged condition was inside its recipe window; empty when the "
                   "recipe judges none",
                   [](const TestRecord& r) -> ExportValue {
                     if (!r.conditions.conditions_in_window) return std::monostate{};
                     return *r.conditions.conditions_in_window;
                   }));
  c.push_back(
      Base("simulated", T::kBool, "", "true when the test ran on a simulator (never a real motor)",
           [](const TestRecord& r) -> ExportValue {
             return r.conditions.simulation.has_value() && !r.conditions.simulation->empty();
           }));
  c.push_back(Base("simulation", T::kText, "", "Why it is a simulation (empty on hardware)",
                   [](const TestRecord& r) -> ExportValue {
                     if (!r.conditions.simulation) return std::monostate{};
                     return *r.conditions.simulation;
                   }));
  AddTestColumns(c, [](int since) { return since > 1; });
  return c;
}

const analysis::Measurement* Find(const TestRecord& r, const std::string& name) {
  for (const auto& m : r.measurements)
    if (m.name == name) return &m;
  return nullptr;
}

// The six fields of every declared measurement, in order. Append only (export_schema.h).
struct MeasurementField {
  const char* key;
  ExportType type;
  bool unit_of_value;  // the unit is the row's <name>_unit
  const char* meaning;
  ExportValue (*get)(const analysis::Measurement&);
};

constexpr MeasurementField kMeasurementFields[] = {
    {"value", ExportType::kNumber, true, "Measured value",
     [](const analysis::Measurement& m) { return Number(m.value); }},
    {"sigma", ExportType::kNumber, true, "Its standard uncertainty",
     [](const analysis::Measurement& m) { return Number(m.sigma); }},
    {"lo", ExportType::kNumber, true, "Lower limit the test judged it by (empty: open)",
     [](const analysis::Measurement& m) -> ExportValue {
       return m.limit.lo ? Number(*m.limit.lo) : ExportValue{};
     }},
    {"hi", ExportType::kNumber, true, "Upper limit the test judged it by (empty: open)",
     [](const analysis::Measurement& m) -> ExportValue {
       return m.limit.hi ? Number(*m.limit.hi) : ExportValue{};
     }},
    {"unit", ExportType::kText, false, "Unit of value, sigma, lo and hi",
     [](const analysis::Measurement& m) { return Text(m.unit); }},
    {"outcome", ExportType::kText, false, "PASS, FAIL or UNSET (not judged)",
     [](const analysis::Measurement& m) { return Text(analysis::ToString(m.outcome)); }},
};

}  // namespace

const char* ToString(ExportType t) {
  switch (t) {
    case ExportType::kInteger:
      return "integer";
    case ExportType::kNumber:
      return "number";
    case ExportType::kText:
      return "text";
    case ExportType::kTime:
      return "time";
    case ExportType::kBool:
      return "bool";
  }
  return "?";
}

std::vector<std::string> ExportMeasurementNames(const std::vector<std::string>& extra) {
  std::vector<std::string> names;
  std::set<std::string> seen;
  auto add = [&](const std::string& n) {
    if (seen.insert(n).second) names.push_back(n);
  };
  for (std::string_view n : analysis::names::kAll) add(std::string(n));
  for (const std::string& n : extra) add(n);
  return names;
}

std::vector<ExportColumn> ExportColumns(const std::vector<std::string>& measurement_names) {
  std::vector<ExportColumn> columns = BaseColumns();
  std::set<std::string> seen;
  for (const std::string& name : measurement_names) {
    if (name.empty()) throw std::invalid_argument("export: an empty measurement name");
    if (!seen.insert(name).second)
      throw std::invalid_argument("export: measurement " + name + " declared twice");
    for (const MeasurementField& f : kMeasurementFields) {
      ExportColumn c;
      c.name = name + "_" + f.key;
      c.measurement = name;
      c.key = f.key;
      c.type = f.type;
      c.unit = f.unit_of_value ? "(" + name + "_unit)" : "";
      c.meaning = f.meaning;
      c.get = [name, get = f.get](const TestRecord& r) -> ExportValue {
        const analysis::Measurement* m = Find(r, name);
        return m ? get(*m) : ExportValue{};
      };
      columns.push_back(std::move(c));
    }
  }
  return columns;
}

namespace {

std::string Quote(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string q = "\"";
  for (char ch : s) q += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return q + "\"";
}

std::string CsvCell(const ExportValue& v) {
  struct Visit {
    std::string operator()(std::monostate) const { return ""; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const {
      char buf[64];
      const auto res = std::to_chars(buf, buf + sizeof buf, d);  // shortest round trip
      return std::string(buf, res.ptr);
    }
    std::string operator()(const std::string& s) const { return Quote(s); }
    std::string operator()(bool b) const { return b ? "true" : "false"; }
  };
  return std::visit(Visit{}, v);
}

nlohmann::ordered_json JsonCell(const ExportValue& v) {
  struct Visit {
    nlohmann::ordered_json operator()(std::monostate) const { return nullptr; }
    nlohmann::ordered_json operator()(std::int64_t i) const { return i; }
    nlohmann::ordered_json operator()(double d) const {
      if (!std::isfinite(d)) return nullptr;
      return d;
    }
    nlohmann::ordered_json operator()(const std::string& s) const { return s; }
    nlohmann::ordered_json operator()(bool b) const { return b; }
  };
  return std::visit(Visit{}, v);
}

}  // namespace

std::string ExportCsvHeader(const std::vector<ExportColumn>& columns) {
  std::string line;
  for (const auto& c : columns) line += (line.empty() ? "" : ",") + Quote(c.name);
  return line + "\n";
}

std::string ExportCsvRow(const std::vector<ExportColumn>& columns, const TestRecord& record) {
  std::string line;
  for (std::size_t i = 0; i < columns.size(); ++i) {
    if (i > 0) line += ",";
    line += CsvCell(columns[i].get(record));
  }
  return line + "\n";
}

nlohmann::ordered_json ExportJsonRow(const std::vector<ExportColumn>& columns,
                                     const TestRecord& record) {
  nlohmann::ordered_json row = nlohmann::ordered_json::object();
  nlohmann::ordered_json measurements = nlohmann::ordered_json::object();
  for (const auto& c : columns) {
    if (c.measurement.empty())
      row[c.key] = JsonCell(c.get(record));
    else
      measurements[c.measurement][c.key] = JsonCell(c.get(record));
  }
  row["measurements"] = std::move(measurements);
  return row;
}

std::string ExportSchemaMarkdown(const std::vector<ExportColumn>& columns) {
  std::string md = "| column | type | unit | meaning |\n|---|---|---|---|\n";
  for (const auto& c : columns)
    md += "| `" + c.name + "` | " + ToString(c.type) + " | " + c.unit + " | " + c.meaning + " |\n";
  return md;
}

std::vector<std::string> ExportUndeclared(const std::vector<ExportColumn>& columns,
                                          const TestRecord& record) {
  std::set<std::string> declared;
  for (const auto& c : columns)
    if (!c.measurement.empty()) declared.insert(c.measurement);
  std::vector<std::string> out;
  for (const auto& m : record.measurements)
    if (!declared.count(m.name)) out.push_back(m.name);
  return out;
}

}  // namespace eol::db
