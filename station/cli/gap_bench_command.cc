// `eol gap-bench`: the blind benchmark of the gap diagnosis (analysis/bench/gap_bench.h). Prints
// one line per case, the confusion matrix, top-1 accuracy (overall and on oracle-separable cases),
// band coverage, the held-out shrink of g and how often a strong effect was called "none".
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "analysis/bench/gap_bench.h"
#include "analysis/text.h"
#include "station/bench/gap_independent_bench.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/progress.h"

namespace eol::station::cli {
namespace {

struct GapBenchArgs {
  int cases = 200;
  std::uint64_t seed = 1;
  bool json = false;
  bool quiet = false;
  std::vector<std::string> independent;
};

std::string Pct(double x) { return analysis::Percent(x, 1); }

void PrintMatrix(std::ostream& out, const analysis::GapBenchSummary& s) {
  out << "confusion matrix (rows: hidden effect, columns: diagnosis)\n";
  std::vector<std::string> shorts;
  for (const std::string& l : s.diagnosed_labels) shorts.push_back(l.substr(0, 6));
  char buf[64];
  std::snprintf(buf, sizeof buf, "%-20s", "");
  out << buf;
  for (const std::string& c : shorts) {
    std::snprintf(buf, sizeof buf, "%7s", c.c_str());
    out << buf;
  }
  out << "\n";
  for (std::size_t r = 0; r < s.truth_labels.size(); ++r) {
    std::snprintf(buf, sizeof buf, "%-20s", s.truth_labels[r].c_str());
    out << buf;
    for (int v : s.confusion[r]) {
      std::snprintf(buf, sizeof buf, "%7d", v);
      out << buf;
    }
    out << "\n";
  }
}

void PrintClass(std::ostream& out, const char* what, const IndependentGapClass& k) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%-34s %3d / %3d separable, %3d / %3d all; a pair answered %d\n",
                what, k.separable_right, k.separable, k.right, k.cases, k.pair_answered);
  out << buf;
}

// The independent generator's cases in DIR (station/bench/gap_independent_bench.h).
int RunIndependent(const std::string& dir, const GapBenchArgs& a) {
  std::ostream& out = a.json ? std::cerr : std::cout;
  const IndependentGapSummary s = RunIndependentGapCases(dir, [&](const IndependentGapCase& c) {
    if (a.quiet) return;
    char line[320];
    std::snprintf(line, sizeof line, "%s %-6s %-44s S %7.1f -> %-44s %s%s\n", c.name.c_str(),
                  c.cls.c_str(), c.hidden.c_str(), c.strength, c.answer.c_str(),
                  c.right ? "ok " : "MISS", c.separable ? "" : " (not separable)");
    out << line << std::flush;
  });
  out << "\nindependent cases " << dir << " (" << s.cases.size() << " cases, "
      << static_cast<int>(s.seconds + 0.5) << " s)\n";
  PrintClass(out, "none (calibration only): `none`", s.none);
  PrintClass(out, "one effect: named alone", s.single);
  PrintClass(out, "two effects: named exactly", s.pair);
  if (a.json) {
    nlohmann::json cases = nlohmann::json::array();
    for (const auto& c : s.cases)
      cases.push_back({{"case", c.name},
                       {"class", c.cls},
                       {"hidden", c.hidden},
                       {"separable", c.separable},
                       {"strength", c.strength},
                       {"answer", c.answer},
                       {"right", c.right}});
    auto cls = [](const IndependentGapClass& k) {
      return nlohmann::json{{"cases", k.cases},
                            {"right", k.right},
                            {"separable", k.separable},
                            {"separable_right", k.separable_right},
                            {"pair_answered", k.pair_answered}};
    };
    std::cout << nlohmann::json{{"independent", dir},  {"seconds", s.seconds},
                                {"none", cls(s.none)}, {"single", cls(s.single)},
                                {"pair", cls(s.pair)}, {"per_case", cases}}
                     .dump()
              << std::endl;
  }
  return 0;
}

int RunGapBenchCommand(const GapBenchArgs& a) {
  for (const std::string& dir : a.independent) RunIndependent(dir, a);
  if (a.cases == 0) return 0;
  analysis::GapBenchOptions o;
  o.cases = a.cases;
  o.seed = a.seed;
  std::ostream& out = a.json ? std::cerr : std::cout;
  const auto start = std::chrono::steady_clock::now();
  // The progress line would break the per-case lines where they reach the terminal: it is
  // drawn when they do not (--quiet, or results piped).
  auto progress =
      std::make_unique<Progress>("gap-bench", a.quiet || (!a.json && isatty(STDOUT_FILENO) != 1));
  int finished = 0;
  const analysis::GapBenchSummary s =
      analysis::RunGapBench(o, [&](const analysis::GapBenchCase& c) {
        progress->Update("cases", ++finished, o.cases);
        if (a.quiet) return;
        char line[256];
        std::snprintf(line, sizeof line,
                      "[%4d] %-20s S %6.1f f0 %5.0f Hz -> %-34s %s%s g %.2f -> %.2f\n", c.index,
                      c.truth.c_str(), c.strength, c.nominal_f0_hz, c.diagnosed.c_str(),
                      c.correct ? "ok " : "MISS", c.oracle_separable ? "" : " (not separable)",
                      c.heldout_before, c.heldout_after);
        out << line << std::flush;
      });
  progress.reset();  // ends the line before the results
  if (!s.usable) {
    std::cerr << "eol gap-bench: " << s.message << "\n";
    return 2;
  }
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out << "\n";
  PrintMatrix(out, s);
  char buf[768];
  std::snprintf(
      buf, sizeof buf,
      "\ncases %d (seed %llu), %.1f s\n"
      "top-1 accuracy            %s overall, %s on %d oracle-separable cases (target >= 90 %%)\n"
      "band covers the effect    %s of %d cases with an effect and a band (%d effect "
      "cases without a band)\n"
      "held-out g after the fix  median %.3f, 90th percentile %.3f, %s within 1.3 "
      "(target: within 1.3), over %d correctly named cases\n"
      "held-out shrink of g      median after/before %.3f; median share of the excess "
      "g^2 - 1 explained %s\n"
      "'none' for strong effects %d of %d (target 0)\n",
      a.cases, static_cast<unsigned long long>(a.seed), seconds, Pct(s.top1).c_str(),
      Pct(s.top1_separable).c_str(), s.separable, Pct(s.band_coverage).c_str(), s.band_cases,
      s.effect_cases_without_band, s.median_heldout_after, s.p90_heldout_after,
      Pct(s.heldout_within_1_3).c_str(), s.heldout_cases, s.median_heldout_shrink,
      Pct(s.median_heldout_excess_explained).c_str(), s.none_for_strong, s.strong_cases);
  out << buf;
  if (s.errors > 0) out << "cases that could not run: " << s.errors << "\n";
  if (a.json) {
    nlohmann::json cases = nlohmann::json::array();
    for (const auto& c : s.cases)
      cases.push_back({{"index", c.index},
                       {"truth", c.truth},
                       {"truth_params", c.truth_params},
                       {"strength", c.strength},
                       {"strong", c.strong},
                       {"nominal_f0_hz", c.nominal_f0_hz},
                       {"diagnosed", c.diagnosed},
                       {"correct", c.correct},
                       {"oracle_separable", c.oracle_separable},
                       {"band_reported", c.band_reported},
                       {"band_covers", c.band_covers},
                       {"gap_before", c.gap_before},
                       {"gap_after", c.gap_after},
                       {"heldout_gap_before", c.heldout_before},
                       {"heldout_gap_after", c.heldout_after}});
    const nlohmann::json j = {
        {"cases", a.cases},
        {"seed", a.seed},
        {"seconds", seconds},
        {"truth_labels", s.truth_labels},
        {"diagnosed_labels", s.diagnosed_labels},
        {"confusion", s.confusion},
        {"top1", s.top1},
        {"top1_separable", s.top1_separable},
        {"separable", s.separable},
        {"band_coverage", s.band_coverage},
        {"band_cases", s.band_cases},
        {"effect_cases_without_band", s.effect_cases_without_band},
        {"median_heldout_after", s.median_heldout_after},
        {"p90_heldout_after", s.p90_heldout_after},
        {"heldout_within_1_3", s.heldout_within_1_3},
        {"median_heldout_shrink", s.median_heldout_shrink},
        {"median_heldout_excess_explained", s.median_heldout_excess_explained},
        {"heldout_cases", s.heldout_cases},
        {"strong_cases", s.strong_cases},
        {"none_for_strong", s.none_for_strong},
        {"errors", s.errors},
        {"per_case", cases}};
    std::cout << j.dump() << std::endl;
  }
  return 0;
}

}  // namespace

void AddGapBenchCommand(CLI::App& app) {
  auto a = std::make_shared<GapBenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "gap-bench",
      "Blind benchmark of `eol gap`: N cases from the simulator (random nominal unit, noise and\n"
      "one hidden effect or none at a random detectable strength), diagnosed without the\n"
      "label; prints the confusion matrix, top-1 accuracy (overall and on cases an oracle with\n"
      "the true model families can separate), band coverage, held-out shrink of g, and how\n"
      "often a strong effect was called 'none' (analysis/bench/gap_bench.h defines each).");
  cmd->add_option("--cases", a->cases, "Number of cases (0: only the --independent ones)")
      ->capture_default_str()
      ->check(Between(0, 100000));
  cmd->add_option("--independent", a->independent,
                  "Also diagnose the blind cases an independent generator wrote into DIR "
                  "(truth.json: tests/peers/independent_gap_cases.py, "
                  "independent_tolerance_cases.py); repeatable")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--seed", a->seed, "Seed (the same seed gives the same cases)")
      ->capture_default_str();
  cmd->add_flag("--json", a->json,
                "Print the summary and every case as one JSON object on stdout "
                "(the text goes to stderr)");
  cmd->add_flag("--quiet", a->quiet, "No line per case");
  cmd->callback([a] { RunGuarded("gap-bench", [&] { return RunGapBenchCommand(*a); }); });
}

}  // namespace eol::station::cli
