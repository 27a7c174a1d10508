// `eol pod --hits FILE [--link logit|probit] [--scale linear|log] [--confidence 0.95]
// [--pod-svg FILE] [--f0-limit HZ]... [--json]`: probability of detection from hit/miss data
// (analysis/qc/pod.h, MIL-HDBK-1823A), e.g. the per-unit table of
// tests/peers/population_rejects.py; the hits CSV and the figure: station/reports/pod_chart.h
// (shared with POST /api/pod.svg). `eol pod --from-db DB [--confidence 0.95] [--json]`: instead of
// a hits table, the store's teardown findings (station/reports/teardown_review.h):
// confirmed-defective units the station failed (hits) and passed (misses), the share caught with
// its exact lower bound, and the false rejects (failed units teardown found not defective). Exit: 0
// every class fitted, 1 a class could not be fitted (the reason is printed) or the store has no
// confirmed-defective unit with a PASS/FAIL verdict, 2 usage.
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
#include "station/reports/pod_chart.h"
#include "station/reports/teardown_review.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct PodArgs {
  std::string hits;
  std::string from_db;
  analysis::PodOptions options;
  std::string svg;
  std::vector<double> f0_limits;
  bool json = false;
};

std::string Bound(double v) {
  return std::isfinite(v) ? std::to_string(v) : std::string("none (not bounded by the data)");
}

void PrintUnits(const char* what, const std::vector<ReviewedUnit>& units) {
  for (const ReviewedUnit& u : units)
    std::cout << "  " << what << ": " << u.finding.serial << " (test #"
              << (u.finding.test_id ? std::to_string(*u.finding.test_id) : "-") << " "
              << analysis::ToString(u.verdict) << ", teardown " << u.finding.at << " by "
              << u.finding.by << (u.finding.note.empty() ? "" : ": " + u.finding.note) << ")\n";
}

int RunPodFromStore(const PodArgs& a) {
  auto store = db::Store::Open(a.from_db, db::Store::Role::kReadOnly);
  const TeardownReview r = ReviewTeardowns(*store, a.options.confidence);
  const std::size_t n = r.hits.size() + r.misses.size();
  if (a.json) {
    std::cout << json{{"from_db", a.from_db}, {"teardown", ReviewJson(r)}}.dump() << std::endl;
    return n > 0 ? 0 : 1;
  }
  std::cout << "teardown findings in " << a.from_db << ": " << n
            << " confirmed defective with a verdict: " << r.hits.size() << " hit(s) (FAIL), "
            << r.misses.size() << " miss(es) (PASS)\n";
  if (n > 0)
    std::cout << "  share caught " << r.pod << ", " << 100.0 * r.confidence << " % lower bound "
              << r.pod_lower << " (exact binomial; no defect sizes, so no "
              << "POD curve)\n";
  PrintUnits("miss", r.misses);
  std::cout << "false rejects (FAIL, teardown found not defective): " << r.false_rejects.size()
            << "; confirmed good (PASS, not defective): " << r.confirmed_good.size()
            << "; without a PASS/FAIL verdict: " << r.no_verdict.size() << "\n";
  PrintUnits("false reject", r.false_rejects);
  PrintUnits("no verdict", r.no_verdict);
  if (n == 0) std::cout << "no confirmed-defective unit: record findings with `eol teardown`\n";
  return n > 0 ? 0 : 1;
}

int RunPod(const PodArgs& a) {
  if (!a.from_db.empty()) return RunPodFromStore(a);
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
      "(columns size, hit; optional class, f0_hz), or hits and misses of the store's teardown\n"
      "findings (--from-db). Exit: 0 fitted, 1 a class could not be fitted (or no\n"
      "confirmed-defective unit in the store), 2 usage error.");
  CLI::Option* hits = cmd->add_option("--hits", args->hits, "Hits CSV")->check(CLI::ExistingFile);
  cmd->add_option("--from-db", args->from_db,
                  "Instead of --hits: the station store's teardown findings (`eol teardown`):\n"
                  "confirmed-defective units failed (hits) and passed (misses), the share\n"
                  "caught with its exact lower bound at --confidence, and the false rejects")
      ->check(CLI::ExistingFile)
      ->excludes(hits);
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
    if (args->hits.empty() && args->from_db.empty())
      throw CLI::RequiredError("--hits or --from-db");
    RunGuarded("pod", [&] { return RunPod(*args); });
  });
}

}  // namespace eol::station::cli
