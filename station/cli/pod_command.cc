// `eol pod --hits FILE [--link logit|probit] [--scale linear|log] [--confidence 0.95]
// [--pod-svg FILE] [--f0-limit HZ]... [--json]`: probability of detection from hit/miss data
// (analysis/qc/pod.h, MIL-HDBK-1823A), e.g. the per-unit table of
// tests/peers/population_rejects.py. The hits file is CSV with a header naming at least the
// columns size (the defect size a, > 0 for a defective unit, 0 for a good one) and hit (1 the
// unit was rejected, 0 it passed); optional columns class (one POD per class, default "all")
// and f0_hz (the fitted resonance, for the figure's distributions; empty when not fitted).
// Good units (size 0) are not part of any POD fit; they are drawn in the figure.
// Exit: 0 every class fitted, 1 a class could not be fitted (the reason is printed), 2 usage.
#include <cmath>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

#include "analysis/qc/pod.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/pod_svg.h"
#include "station/cli/progress.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct PodArgs {
  std::string hits;
  analysis::PodOptions options;
  std::string svg;
  std::vector<double> f0_limits;
  bool json = false;
};

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

double ParseNumber(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size())
    throw std::runtime_error(where + ": '" + text + "' is not a number");
  return v;
}

struct HitsFile {
  std::map<std::string, std::vector<analysis::HitMiss>> defective;  // by class
  std::map<std::string, std::vector<double>> f0_hz;                 // by class, every unit
};

HitsFile ReadHits(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the hits file '" + path + "'");
  std::string line;
  if (!std::getline(in, line)) throw std::runtime_error(path + ": empty (no header)");
  const std::vector<std::string> header = SplitCsv(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* need : {"size", "hit"})
    if (!col.count(need))
      throw std::runtime_error(path + ": the header has no column '" + need +
                               "' (needs size and hit; class and f0_hz optional)");
  HitsFile h;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    const std::vector<std::string> cells = SplitCsv(line);
    const std::string where = path + ":" + std::to_string(n);
    auto cell = [&](const std::string& name) -> std::string {
      const std::size_t i = col.at(name);
      if (i >= cells.size()) throw std::runtime_error(where + ": no value in column " + name);
      return cells[i];
    };
    const std::string cls = col.count("class") ? cell("class") : "all";
    const double size = ParseNumber(cell("size"), where + " size");
    const std::string hit = cell("hit");
    if (hit != "0" && hit != "1") throw std::runtime_error(where + ": hit must be 0 or 1");
    if (size < 0.0) throw std::runtime_error(where + ": size must be >= 0");
    if (size > 0.0) h.defective[cls].push_back({size, hit == "1"});
    if (col.count("f0_hz") && col.at("f0_hz") < cells.size() && !cells[col.at("f0_hz")].empty())
      h.f0_hz[cls].push_back(ParseNumber(cells[col.at("f0_hz")], where + " f0_hz"));
  }
  if (h.defective.empty())
    throw std::runtime_error(path + ": no defective unit (size > 0): nothing to fit");
  return h;
}

std::string Bound(double v) {
  return std::isfinite(v) ? std::to_string(v) : std::string("none (not bounded by the data)");
}

int RunPod(const PodArgs& a) {
  const HitsFile h = ReadHits(a.hits);
  json fits = json::object();
  std::vector<PodCurve> curves;
  bool all_usable = true;
  {
    // Each class's fit, before anything is printed (the line ends before the results).
    Progress progress("pod");
    std::int64_t done = 0;
    const auto total = static_cast<std::int64_t>(h.defective.size());
    for (const auto& [cls, data] : h.defective) {
      progress.Update("classes fitted", done++, total);
      curves.push_back({cls, analysis::FitPod(data, a.options), data});
    }
    progress.Update("classes fitted", total, total);
  }
  for (const auto& curve : curves) {
    const std::string& cls = curve.label;
    const analysis::PodSummary& s = curve.fit;
    all_usable = all_usable && s.usable;
    fits[cls] = analysis::PodToJson(s);
    if (!a.json) {
      std::cout << cls << ": " << s.message << "\n";
      if (s.usable)
        std::cout << "  a50 " << s.a50 << ", a90 " << s.a90 << ", a90/95 " << Bound(s.a90_95_lr)
                  << " (likelihood ratio), " << Bound(s.a90_95_wald) << " (Wald)\n";
    }
  }
  if (!a.svg.empty()) {
    std::vector<F0Group> groups;
    for (const auto& [cls, f0] : h.f0_hz) groups.push_back({cls, f0});
    std::vector<F0Limit> limits;
    for (double f : a.f0_limits) limits.push_back({"f0 limit", f});
    WritePodSvg(a.svg, "POD from " + a.hits, curves, groups, limits);
    if (!a.json) std::cout << "figure: " << a.svg << "\n";
  }
  if (a.json) std::cout << json{{"hits", a.hits}, {"pod", fits}}.dump() << std::endl;
  return all_usable ? 0 : 1;
}

}  // namespace

void AddPodCommand(CLI::App& app) {
  auto args = std::make_shared<PodArgs>();
  CLI::App* cmd = app.add_subcommand(
      "pod",
      "Probability of detection from hit/miss data (MIL-HDBK-1823A): POD(a) by maximum\n"
      "likelihood, a50, a90 and a90/95 (likelihood ratio and Wald), per class of the hits CSV\n"
      "(columns size, hit; optional class, f0_hz). Exit: 0 fitted, 1 a class could not be\n"
      "fitted, 2 usage error.");
  cmd->add_option("--hits", args->hits, "Hits CSV")->required()->check(CLI::ExistingFile);
  cmd->add_option_function<std::string>(
         "--link", [args](const std::string& n) { args->options.link = analysis::ParsePodLink(n); },
         "logit (default) or probit")
      ->check(CLI::IsMember({"logit", "probit"}));
  cmd->add_option_function<std::string>(
         "--scale",
         [args](const std::string& n) { args->options.scale = analysis::ParsePodScale(n); },
         "linear (x = a, default) or log (x = ln a)")
      ->check(CLI::IsMember({"linear", "log"}));
  cmd->add_option("--confidence", args->options.confidence, "One-sided confidence of a90/95")
      ->capture_default_str();
  cmd->add_option("--pod-level", args->options.pod_level, "POD of the a90 point")
      ->capture_default_str();
  cmd->add_option("--pod-svg", args->svg, "Write the POD figure (SVG) to this file");
  cmd->add_option("--f0-limit", args->f0_limits, "Taught f0 limit(s) to draw, Hz");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] {
    std::string why;
    if (!args->options.IsValid(&why)) throw CLI::ValidationError("--confidence/--pod-level", why);
    RunGuarded("pod", [&] { return RunPod(*args); });
  });
}

}  // namespace eol::station::cli
