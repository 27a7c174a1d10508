// `eol pod --hits FILE [--link logit|probit] [--scale linear|log] [--confidence 0.95]
// [--pod-svg FILE] [--f0-limit HZ]... [--json]`: probability of detection from hit/miss data
// (analysis/qc/pod.h, MIL-HDBK-1823A), e.g. the per-unit table of
// tests/peers/population_rejects.py; the hits CSV and the figure: station/pod_chart.h (shared
// with POST /api/pod.svg).
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
#include "station/cli/progress.h"
#include "station/pod_chart.h"

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

std::string Bound(double v) {
  return std::isfinite(v) ? std::to_string(v) : std::string("none (not bounded by the data)");
}

int RunPod(const PodArgs& a) {
  const HitsTable h = ReadHitsFile(a.hits);
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
    std::vector<F0Limit> limits;
    for (double f : a.f0_limits) limits.push_back({"f0 limit", f});
    WritePodSvg(a.svg, "POD from " + a.hits, curves, F0Groups(h), limits);
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
