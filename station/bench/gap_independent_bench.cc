#include "station/bench/gap_independent_bench.h"

#include <chrono>
#include <map>
#include <set>
#include <sstream>

#include "drivers/io/json_config.h"
#include "station/reports/gap_diagnosis.h"

namespace eol::station {
namespace {

// The generator's hidden effect -> the names the diagnosis may answer for it.
const std::map<std::string, std::set<std::string>>& Expected() {
  static const std::map<std::string, std::set<std::string>> names = {
      {"coupled_inertia", {"coupled_inertia"}},
      {"fractional_inductance", {"lossy_inductance", "fractional_inductance"}},
      {"eddy_branch", {"lossy_inductance", "fractional_inductance"}},
      {"channel_delay", {"channel_delay"}},
      {"stray_capacitance", {"stray_capacitance"}},
      {"fixture_spring", {"fixture_compliance"}},
      {"series_resistance", {"series_resistance"}}};
  return names;
}

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  for (std::string x; std::getline(in, x, '+');) out.push_back(x);
  return out;
}

bool Names(const std::string& answer, const std::string& hidden) {
  const auto it = Expected().find(hidden);
  return it != Expected().end() && it->second.count(answer) > 0;
}

std::string Diagnose(const std::string& base, double sigma_dof) {
  try {
    GapRunOptions o;
    o.sigma_dof = sigma_dof;
    GapReport r;
    ReadGapInputs(base + "-sim.csv", {base + "-meas.csv"}, o, &r);
    DiagnoseGapReport(o, &r);
    return r.gap.effect;
  } catch (const std::exception& e) {
    return std::string("error: ") + e.what();
  }
}

void Count(const IndependentGapCase& c, IndependentGapClass* k) {
  ++k->cases;
  k->right += c.right ? 1 : 0;
  k->pair_answered += c.pair_answered ? 1 : 0;
  if (!c.separable) return;
  ++k->separable;
  k->separable_right += c.right ? 1 : 0;
}

}  // namespace

bool NamesExactly(const std::string& answer, const std::string& hidden) {
  if (hidden == "none") return answer == "none";
  const std::vector<std::string> got = Split(answer), want = Split(hidden);
  if (got.size() != want.size() || got.empty() || got.size() > 2) return false;
  if (got.size() == 1) return Names(got[0], want[0]);
  return (Names(got[0], want[0]) && Names(got[1], want[1])) ||
         (Names(got[0], want[1]) && Names(got[1], want[0]));
}

IndependentGapSummary RunIndependentGapCases(
    const std::string& dir, const std::function<void(const IndependentGapCase&)>& on_case) {
  const auto start = std::chrono::steady_clock::now();
  const nlohmann::json truth = io::ReadJsonFile(dir + "/truth.json");
  if (!truth.is_array()) throw io::ConfigError(dir + "/truth.json: must be an array of cases");
  IndependentGapSummary s;
  for (const nlohmann::json& t : truth) {
    IndependentGapCase c;
    c.name = t.at("case").get<std::string>();
    c.hidden = t.at("effect").get<std::string>();
    c.cls = t.contains("class")  ? t["class"].get<std::string>()
            : c.hidden == "none" ? "none"
                                 : "single";
    c.separable = t.value("separable", true);
    c.strength = t.value("strength", 0.0);
    c.answer = Diagnose(dir + "/" + c.name, t.value("sigma_dof", 0.0));
    c.right = NamesExactly(c.answer, c.hidden);
    c.pair_answered = c.answer.rfind("error", 0) != 0 && Split(c.answer).size() == 2;
    Count(c, c.cls == "none" ? &s.none : c.cls == "pair" ? &s.pair : &s.single);
    if (on_case) on_case(c);
    s.cases.push_back(std::move(c));
  }
  s.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return s;
}

}  // namespace eol::station
