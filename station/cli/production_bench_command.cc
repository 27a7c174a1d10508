// `eol production-bench --units N --seed S [--json]`: the production benchmark of learned
// limits (analysis/bench/production_bench.h) with the recipe's excitation, analysis and
// declared measurements. Prints, per defect class, units and how many each rule passes
// (escapes) or rejects (false rejects for good units): taught limits, the recipe's own limits,
// and the naive |Z| peak in a fixed window.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>

#include "analysis/bench/production_bench.h"
#include "analysis/text.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/progress.h"
#include "station/daemon/data_files.h"
#include "station/daemon/recipe.h"
#include "station/reports/pod_chart.h"

namespace eol::station::cli {
namespace {

using nlohmann::json;

struct BenchArgs {
  std::string recipe = DefaultRecipePath();
  analysis::ProductionBenchOptions options;
  bool json = false;
  std::string pod_svg;
};

std::string Percent(double v) { return analysis::Percent(v, 2); }

// Units of class c that took more than one look (a sequential recipe).
int ExtendedOf(const analysis::ProductionBenchSummary& s, analysis::DefectClass c) {
  for (std::size_t i = 0; i < analysis::kAllDefectClasses.size(); ++i)
    if (analysis::kAllDefectClasses[i] == c) return s.extended[i];
  return 0;
}

json SummaryJson(const analysis::ProductionBenchSummary& s, const BenchArgs& a) {
  json classes = json::array();
  for (analysis::DefectClass c : analysis::kAllDefectClasses) {
    json rules = json::object();
    for (analysis::BenchRule r : analysis::kBenchRules) {
      const analysis::ClassCounts& k = s.Counts(r, c);
      rules[analysis::ToString(r)] = {{"pass", k.pass}, {"fail", k.fail}, {"error", k.error}};
    }
    classes.push_back({{"class", analysis::ToString(c)},
                       {"units", s.Counts(analysis::BenchRule::kTaught, c).units},
                       {"extended", ExtendedOf(s, c)},
                       {"rules", rules}});
  }
  json rates = json::object();
  for (analysis::BenchRule r : analysis::kBenchRules) {
    json esc = json::object();
    for (analysis::DefectClass c : analysis::kAllDefectClasses)
      if (c != analysis::DefectClass::kGood) esc[analysis::ToString(c)] = s.EscapeRate(r, c);
    rates[analysis::ToString(r)] = {{"false_reject_rate", s.FalseRejectRate(r)},
                                    {"escape_rate", esc}};
  }
  json limits = json::array();
  for (const auto& l : s.teach.limits) limits.push_back(LimitJson(l));
  json pod = json::array();
  for (const auto& w : s.pod) {
    json f = analysis::PodToJson(w.fit);
    f["name"] = w.name;
    f["defect"] = analysis::ToString(w.defect);
    pod.push_back(f);
  }
  return {{"usable", s.usable},
          {"pod", pod},
          {"message", s.message},
          {"units", s.units},
          {"seed", a.options.seed},
          {"golden_units", a.options.golden_units},
          {"threads", a.options.threads},
          {"recipe", a.recipe},
          {"teach",
           {{"message", s.teach.message},
            {"units_used", s.teach.units_used},
            {"k", s.teach.k_factor},
            {"units_needed", s.teach.units_needed},
            {"limits", limits}}},
          {"classes", classes},
          {"rates", rates},
          {"seconds", s.seconds},
          {"golden_seconds", s.golden_seconds},
          {"ms_per_unit", 1000.0 * s.seconds / std::max(1, s.units + a.options.golden_units)}};
}

int RunBench(BenchArgs a) {
  const Recipe r = LoadRecipe(a.recipe);
  analysis::ProductionBenchOptions& o = a.options;
  o.excitation = r.excitation;
  o.periods = r.periods;
  if (r.sequential) {
    o.max_extensions = r.sequential->max_extensions;
    o.extend_periods = r.sequential->extend_periods;
    o.confidence_z = r.sequential->confidence_z;
  }
  o.fit = r.analysis.fit;
  o.declared = r.limits;
  o.recipe_masks = r.masks;
  o.recipe_bond_index = r.bond_index;
  o.naive.search_lo_hz = r.analysis.fit.f0_min_hz;
  o.naive.search_hi_hz = r.analysis.fit.f0_max_hz;
  analysis::ProductionBenchSummary s;
  {
    Progress progress("production-bench");
    o.progress = progress.Callback();
    s = analysis::RunProductionBench(o);
  }
  if (!s.usable) {
    std::cerr << "eol production-bench: " << s.message << std::endl;
    if (a.json) std::cout << json{{"usable", false}, {"error", s.message}}.dump() << std::endl;
    return 1;
  }
  if (!a.pod_svg.empty()) {
    std::vector<PodCurve> curves;
    for (const auto& w : s.pod) curves.push_back({w.name, w.fit, w.data});
    std::vector<F0Group> groups;
    for (std::size_t c = 0; c < analysis::kAllDefectClasses.size(); ++c)
      if (!s.f0_hz[c].empty())
        groups.push_back({analysis::ToString(analysis::kAllDefectClasses[c]), s.f0_hz[c]});
    std::vector<F0Limit> limits;
    for (const auto& l : s.teach.limits)
      if (l.name == "resonance_f_hz") {
        if (l.limit.lo) limits.push_back({"f0 lo", *l.limit.lo});
        if (l.limit.hi) limits.push_back({"f0 hi", *l.limit.hi});
      }
    WritePodSvg(a.pod_svg,
                "production bench, seed " + std::to_string(o.seed) + ": POD and fitted f0", curves,
                groups, limits);
  }
  if (a.json) {
    std::cout << SummaryJson(s, a).dump() << std::endl;
    return 0;
  }
  std::cout << "production bench: " << s.units << " units, seed " << o.seed << ", recipe " << r.id
            << " v" << r.version << "\n"
            << "teach: " << s.teach.message << "\n";
  for (const auto& l : s.teach.limits)
    std::cout << "  " << l.name << ": [" << (l.limit.lo ? json(*l.limit.lo).dump() : "-") << ", "
              << (l.limit.hi ? json(*l.limit.hi).dump() : "-") << "]\n";
  std::printf("%-18s %6s | %-22s | %-22s | %-22s\n", "class", "units", "taught pass/fail/err",
              "recipe pass/fail/err", "naive pass/fail");
  for (analysis::DefectClass c : analysis::kAllDefectClasses) {
    const auto& t = s.Counts(analysis::BenchRule::kTaught, c);
    const auto& h = s.Counts(analysis::BenchRule::kRecipe, c);
    const auto& n = s.Counts(analysis::BenchRule::kNaive, c);
    char tb[64], hb[64], nb[64];
    std::snprintf(tb, sizeof tb, "%d/%d/%d", t.pass, t.fail, t.error);
    std::snprintf(hb, sizeof hb, "%d/%d/%d", h.pass, h.fail, h.error);
    std::snprintf(nb, sizeof nb, "%d/%d", n.pass, n.fail);
    std::printf("%-18s %6d | %-22s | %-22s | %-22s\n", analysis::ToString(c), t.units, tb, hb, nb);
  }
  if (a.options.max_extensions > 0) {
    std::cout << "sequential (up to " << a.options.max_extensions << " x "
              << a.options.extend_periods << " more periods while undecided at z "
              << a.options.confidence_z << "): extended";
    int all = 0;
    for (analysis::DefectClass c : analysis::kAllDefectClasses) {
      std::cout << " " << analysis::ToString(c) << " " << ExtendedOf(s, c);
      all += ExtendedOf(s, c);
    }
    std::cout << "; " << Percent(static_cast<double>(all) / std::max(1, s.units)) << " of all\n";
  }
  for (analysis::BenchRule rule : analysis::kBenchRules) {
    std::cout << analysis::ToString(rule) << ": false rejects " << Percent(s.FalseRejectRate(rule))
              << ", escapes";
    for (analysis::DefectClass c : analysis::kAllDefectClasses)
      if (c != analysis::DefectClass::kGood)
        std::cout << " " << analysis::ToString(c) << " " << Percent(s.EscapeRate(rule, c));
    std::cout << "\n";
  }
  for (const auto& w : s.pod) {
    std::cout << "POD " << w.name << " (" << analysis::ToString(w.defect)
              << ", bond stiffness loss a): " << w.fit.message << "\n";
  }
  if (!a.pod_svg.empty()) std::cout << "figure: " << a.pod_svg << "\n";
  std::printf("time: %.1f s (golden and teaching %.1f s), %.2f ms per unit on %d threads\n",
              s.seconds, s.golden_seconds,
              1000.0 * s.seconds / std::max(1, s.units + o.golden_units), o.threads);
  return 0;
}

}  // namespace

void AddProductionBenchCommand(CLI::App& app) {
  auto args = std::make_shared<BenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "production-bench",
      "Simulate a production line (magnet, bond, clamp and temperature spread, defect classes at\n"
      "known rates), teach limits from golden units, judge every unit with the taught limits,\n"
      "the recipe's own limits and a naive |Z|-peak window, and report escapes per defect class\n"
      "and false rejects. Exit: 0 done, 1 the benchmark could not run, 2 usage error.");
  cmd->add_option("--units", args->options.units, "Production units")->capture_default_str();
  cmd->add_option("--seed", args->options.seed, "Seed of the population and the noise")
      ->capture_default_str();
  cmd->add_option("--golden-units", args->options.golden_units, "Good units to teach from")
      ->capture_default_str();
  cmd->add_option("--threads", args->options.threads, "Worker threads")->capture_default_str();
  cmd->add_option("--recipe", args->recipe, "Recipe: excitation, analysis, declared limits")
      ->capture_default_str()
      ->check(CLI::ExistingFile);
  cmd->add_option("--confidence", args->options.teach.confidence, "Teaching confidence")
      ->capture_default_str();
  cmd->add_option("--coverage", args->options.teach.coverage, "Teaching coverage of good units")
      ->capture_default_str();
  std::vector<std::string> methods;  // the names of analysis/qc/teach.h
  for (analysis::TeachMethod m : analysis::kAllTeachMethods)
    methods.push_back(analysis::ToString(m));
  cmd->add_option_function<std::string>(
         "--method",
         [args](const std::string& name) {
           args->options.teach.method = analysis::ParseTeachMethod(name);
         },
         "tolerance_interval (default) or mad")
      ->check(CLI::IsMember(methods));
  cmd->add_option("--pod-units", args->options.pod_units,
                  "Units per POD sweep (one soft magnet, all soft), 0: none")
      ->capture_default_str();
  cmd->add_option("--pod-loss-lo", args->options.pod_loss_lo, "Smallest bond stiffness loss")
      ->capture_default_str();
  cmd->add_option("--pod-loss-hi", args->options.pod_loss_hi, "Largest bond stiffness loss")
      ->capture_default_str();
  cmd->add_option("--pod-svg", args->pod_svg,
                  "Write the figure (POD with its bound and a90/95; f0 per class and the taught "
                  "limits) to this SVG file");
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->callback([args] { RunGuarded("production-bench", [&] { return RunBench(*args); }); });
}

}  // namespace eol::station::cli
