#include "station/cli/golden_inputs.h"

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <stdexcept>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/signal/waveform.h"
#include "db/store.h"
#include "db/test_record.h"
#include "drivers/io/measured_input.h"
#include "station/daemon/qc_service.h"

namespace eol::station::cli {
namespace {

namespace names = analysis::names;

bool EndsWith(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

analysis::GoldenUnit FromMeasured(const std::string& path, const Recipe& recipe) {
  io::MeasuredInput in = io::ReadMeasured(path, {});
  analysis::ImpedanceAnalysis a;
  if (in.kind == io::MeasuredKind::kFrf) {
    if (in.frf.quantity != analysis::Quantity::kImpedanceOhm)
      throw std::runtime_error(path +
                               ": a golden unit must be an impedance FRF (f_hz,re_ohm,im_ohm)");
    a = analysis::AnalyzeImpedance(in.frf, recipe.analysis.fit);
  } else {
    const analysis::MultisineOptions& e = recipe.excitation;
    in.recording.period_samples =
        static_cast<std::size_t>(std::llround(e.sample_rate_hz / e.line_spacing_hz));
    a = analysis::AnalyzeRecording(in.recording,
                                   analysis::BandLines(e.f_lo_hz, e.f_hi_hz, e.line_spacing_hz),
                                   recipe.analysis);
  }
  if (!a.usable) throw std::runtime_error(path + ": not analysable: " + a.message);
  analysis::GoldenUnit u;
  u.label = path;
  for (const auto& [name, e] : a.values) u.values[name] = e.value;
  u.curve = a.frf.frf;
  return u;
}

analysis::GoldenUnit FromAnalyzeJson(const nlohmann::json& j, const std::string& path,
                                     bool known_bad) {
  if (!j.value("usable", false))
    throw std::runtime_error(path + ": the analysis is not usable (\"usable\": false)");
  if (!known_bad && j.contains("verdict") && j.at("verdict").value("outcome", "") != "PASS")
    throw std::runtime_error(path + ": the verdict is " + j.at("verdict").value("outcome", "?") +
                             ": only PASS units are golden units");
  static const std::map<std::string, std::string_view> kParams = {
      {"f0_hz", names::kResonanceFHz},
      {"Q", names::kResonanceQ},
      {"R_ohm", names::kWindingROhm},
      {"L_h", names::kWindingLH},
      {"Rp_ohm", names::kMotionalRpOhm}};
  analysis::GoldenUnit u;
  u.label = path;
  for (const auto& [param, name] : kParams) {
    const auto& p = j.at("params");
    if (p.contains(param)) u.values[std::string(name)] = p.at(param).at("value").get<double>();
  }
  const auto& p = j.at("params");
  if (p.contains("Rp_ohm") && p.contains("f0_hz") && p.contains("Q")) {
    analysis::MotionalImpedance m;
    m.rp_ohm = p.at("Rp_ohm").at("value").get<double>();
    m.f0_hz = p.at("f0_hz").at("value").get<double>();
    m.q = p.at("Q").at("value").get<double>();
    u.values[std::string(names::kMotionalResidueOhmPerS)] = m.ResidueOhmPerS();
  }
  // The clamp pressure `eol analyze --clamp-pressure-bar` kept (f0_pressure.h).
  const auto conditions = j.value("conditions", db::TestConditions{});
  if (conditions.clamp_pressure_bar)
    u.values[std::string(names::kClampPressureBar)] = *conditions.clamp_pressure_bar;
  if (j.contains("fit") && j.at("fit").contains("chi2_per_dof"))
    u.values[std::string(names::kFitChi2PerDof)] = j.at("fit").at("chi2_per_dof").get<double>();
  // What only a recipe's analysis computes (second_mode_chi2_drop): from the verdict's
  // measurements of `eol analyze --recipe R --json`.
  if (j.contains("verdict") && j.at("verdict").contains("measurements"))
    for (const auto& m : j.at("verdict").at("measurements"))
      if (m.contains("name") && m.contains("value") && m.at("value").is_number() &&
          !u.values.count(m.at("name").get<std::string>()))
        u.values[m.at("name").get<std::string>()] = m.at("value").get<double>();
  return u;
}

}  // namespace

std::vector<analysis::GoldenUnit> ReadGoldenUnits(const std::vector<std::string>& paths,
                                                  const Recipe& recipe,
                                                  std::vector<std::string>* skipped, bool known_bad,
                                                  const analysis::ProgressCallback& progress) {
  if (skipped) skipped->clear();  // nothing is skipped any more: unusable records are refused
  std::vector<analysis::GoldenUnit> units;
  const char* phase = known_bad ? "known-bad files" : "golden files";
  const auto total = static_cast<std::int64_t>(paths.size());
  std::int64_t done = 0;
  for (const std::string& path : paths) {
    if (progress) progress(phase, done++, total);
    if (!EndsWith(path, ".json")) {
      units.push_back(FromMeasured(path, recipe));
      continue;
    }
    std::ifstream in(path);
    if (!in) throw std::runtime_error(path + ": cannot be read");
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(in);
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(path + ": not JSON: " + e.what());
    }
    try {
      const auto is_export_row = [](const nlohmann::json& x) {
        return x.is_object() && x.contains("schema_version");
      };
      if (is_export_row(j) || (j.is_array() && !j.empty() && is_export_row(j.front()))) {
        throw std::runtime_error(
            "rows of the export schema (`eol export --format json`) carry no curves; teach "
            "reads full records: `eol export --format records`");
      } else if (j.is_object() && j.contains("params")) {
        units.push_back(FromAnalyzeJson(j, path, known_bad));
      } else if (j.is_array() || (j.is_object() && j.contains("measurements"))) {
        const nlohmann::json list = j.is_array() ? j : nlohmann::json::array({j});
        for (std::size_t i = 0; i < list.size(); ++i) {
          const db::TestRecord r = list[i].get<db::TestRecord>();
          const std::string label = path + "[" + std::to_string(i) + "] " + r.serial;
          // A golden unit is a good production unit tested with this very recipe: anything
          // else would teach limits from what they must reject, or from another test.
          if (known_bad && r.outcome != analysis::Outcome::kPass &&
              r.outcome != analysis::Outcome::kFail)
            throw std::runtime_error("record " + label + " is " + analysis::ToString(r.outcome) +
                                     ": a known-bad unit needs a PASS or FAIL measurement");
          if (!known_bad && r.outcome != analysis::Outcome::kPass)
            throw std::runtime_error("record " + label + " is " + analysis::ToString(r.outcome) +
                                     ": only PASS records are golden units");
          if (!known_bad && r.kind != db::RecordKind::kProduction)
            throw std::runtime_error("record " + label + " is a " + db::ToString(r.kind) +
                                     " test (a master part), not a production unit");
          if (r.recipe_hash != recipe.hash)
            throw std::runtime_error("record " + label + " was tested with recipe hash " +
                                     (r.recipe_hash.empty() ? "(none)" : r.recipe_hash) + ", not " +
                                     recipe.hash + " (" + recipe.id + " v" +
                                     std::to_string(recipe.version) + ")");
          units.push_back(GoldenFromRecord(r, label));
        }
      } else {
        throw std::runtime_error(
            "neither `eol analyze --json` output (\"params\") nor `eol export --format records` "
            "records (\"measurements\")");
      }
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(path + ": " + e.what());
    } catch (const std::runtime_error& e) {
      const std::string what = e.what();
      if (what.rfind(path, 0) == 0) throw;
      throw std::runtime_error(path + ": " + what);
    }
  }
  if (progress) progress(phase, total, total);
  if (units.empty())
    throw std::runtime_error(known_bad ? "no known-bad unit could be read"
                                       : "no golden unit could be read");
  return units;
}

std::vector<analysis::GoldenUnit> ReadKnownBadFromStore(const std::string& db_path,
                                                        const Recipe& recipe,
                                                        std::vector<std::string>* skipped) {
  if (skipped) skipped->clear();
  auto store = db::Store::Open(db_path, db::Store::Role::kReadOnly);
  std::vector<analysis::GoldenUnit> units;
  int defective = 0;
  for (const db::TeardownEntry& e : store->CurrentTeardowns()) {
    if (e.found != db::TeardownFinding::kDefective) continue;
    ++defective;
    const std::string label = db_path + " " + e.serial + " test #" +
                              (e.test_id ? std::to_string(*e.test_id) : std::string("-"));
    const auto t = e.test_id ? store->Test(*e.test_id, true) : std::nullopt;
    std::string why;
    if (!t)
      why = "its judged test is not in the store";
    else if (t->outcome != analysis::Outcome::kPass && t->outcome != analysis::Outcome::kFail)
      why = std::string("its judged test is ") + analysis::ToString(t->outcome) +
            " (no measurement to place limits against)";
    else if (t->recipe_hash != recipe.hash)
      why = "tested with recipe " + t->recipe_id + " v" + std::to_string(t->recipe_version) + " (" +
            t->recipe_hash.substr(0, 12) + "), not " + recipe.id + " v" +
            std::to_string(recipe.version) + " (" + recipe.hash.substr(0, 12) + ")";
    if (!why.empty()) {
      if (skipped) skipped->push_back(label + ": " + why);
      continue;
    }
    units.push_back(GoldenFromRecord(*t, label));
  }
  if (units.empty())
    throw std::runtime_error(db_path + ": no confirmed-defective unit tested with " + recipe.id +
                             " v" + std::to_string(recipe.version) + " (" +
                             std::to_string(defective) +
                             " confirmed defective in all; record findings with `eol teardown`)");
  return units;
}

}  // namespace eol::station::cli
