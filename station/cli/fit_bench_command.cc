// `eol fit-bench`: the benchmark of the identification engine (analysis/bench/fit_bench.h) on the
// recipe's measurement of the population's nominal good rotor with the simulated DAQ's noise,
// and the same pipeline in SciPy on the same data for the time ratio
// (station/bench/fit_bench_peer.h). Prints the five figures that
// analysis/README.md "Measured figures" records.
#include <cmath>
#include <iostream>
#include <locale>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "analysis/bench/fit_bench.h"
#include "analysis/sim/population.h"
#include "drivers/sim/sim_daq.h"
#include "station/bench/fit_bench_peer.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/cli/progress.h"
#include "station/daemon/data_files.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

struct FitBenchArgs {
  int runs = 500;
  std::uint64_t seed = 1;
  bool json = false;
  std::string recipe = DefaultRecipePath();
  int check_runs = 200;
  int peer_runs = 20;
  std::string python = "/usr/bin/python3";
  std::string script = DefaultScipyPipelineScript();
  // The record: recipe's unless given; how it is simulated and estimated.
  std::string frf_method;  // empty: the recipe's analysis.frf_method
  std::string sim = "steady_state";
  double series_ohm = 0.0;
  double line_spacing_hz = 0.0;  // 0: the recipe's
  int periods = 0;               // 0: the recipe's
  int transient_periods = -1;    // -1: the recipe's
  int lpm_degree = -1;           // -1: the default of transient_frf.h
  int lpm_half_width = -1;
};

std::string G(double v, int precision = 4) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(precision);
  os << v;
  return os.str();
}

// The benchmark's options: the population's nominal good rotor measured with the recipe's
// excitation and the simulated DAQ's noise, with the command's overrides. Prints the error
// and returns false for a bad --frf-method or --sim.
bool MakeOptions(const FitBenchArgs& a, const Recipe& recipe, analysis::FitBenchOptions* o) {
  const analysis::MotorPopulation population;
  analysis::ClampedRotor rotor;
  rotor.inertia_kg_m2 = population.inertia_kg_m2;
  rotor.k_rotor_nm_per_rad = population.KRotorNmPerRad(false);
  rotor.k_fixture_nm_per_rad = population.KFixtureNmPerRad();
  rotor.q = population.q_good;
  rotor.transmission_nm_per_a = population.transmission_nm_per_a;
  const drivers::SimDaqSettings daq;

  o->truth = rotor.Electrical(population.r_ohm, population.l_h);
  o->excitation = recipe.excitation;
  o->periods = recipe.periods;
  o->transient_periods = recipe.transient_periods;
  o->voltage_noise_v = daq.voltage_noise_v;
  o->current_noise_a = daq.current_noise_a;
  o->analysis = recipe.analysis;
  if (!a.frf_method.empty() && !analysis::ParseFrfMethod(a.frf_method, &o->analysis.frf_method)) {
    std::cerr << "eol fit-bench: --frf-method must be discard_transient or transient_lpm\n";
    return false;
  }
  if (a.sim == "time_domain") {
    o->simulation = analysis::BenchSimulation::kTimeDomain;
  } else if (a.sim != "steady_state") {
    std::cerr << "eol fit-bench: --sim must be steady_state or time_domain\n";
    return false;
  }
  o->series_ohm = a.series_ohm;
  if (a.line_spacing_hz > 0.0) o->excitation.line_spacing_hz = a.line_spacing_hz;
  if (a.periods > 0) o->periods = static_cast<std::size_t>(a.periods);
  if (a.transient_periods >= 0) {
    o->transient_periods = static_cast<std::size_t>(a.transient_periods);
    o->analysis.frf.transient_periods = o->transient_periods;
  }
  if (a.lpm_degree >= 0) o->analysis.lpm.degree = static_cast<std::size_t>(a.lpm_degree);
  if (a.lpm_half_width >= 0)
    o->analysis.lpm.half_width = static_cast<std::size_t>(a.lpm_half_width);
  o->runs = a.runs;
  o->seed = a.seed;
  o->check_runs = a.check_runs;
  o->keep_recordings = static_cast<std::size_t>(std::max(0, std::min(a.peer_runs, a.runs)));
  return true;
}

// The SciPy pipeline on the kept recordings, compared with ours.
struct PeerComparison {
  ScipyPeerResult peer;
  double max_diff_sigma = 0.0;  // largest |f0 difference| in Cramer-Rao bounds
  double ratio = 0.0;           // SciPy's time over ours; NaN when it did not run
};

PeerComparison ComparePeer(const FitBenchArgs& a, const analysis::FitBenchOptions& o,
                           const analysis::FitBenchResult& r) {
  PeerComparison c;
  ScipyPeerResult& peer = c.peer;
  peer.message = "skipped (--peer-runs 0)";
  // The SciPy pipeline re-implements the discarding estimator only.
  if (a.peer_runs > 0 && o.analysis.frf_method != analysis::FrfMethod::kDiscardTransient)
    peer.message = "skipped: the SciPy pipeline implements discard_transient only";
  else if (a.peer_runs > 0)
    peer = RunScipyPipelinePeer(r, o, a.python, a.script);
  for (std::size_t k = 0; peer.ran && k < peer.f0_hz.size() && k < r.kept_f0_hat_hz.size(); ++k)
    c.max_diff_sigma =
        std::max(c.max_diff_sigma, std::abs(peer.f0_hz[k] - r.kept_f0_hat_hz[k]) / r.crb_f0_hz);
  c.ratio = peer.ran ? peer.ms_mean / r.analysis_ms_mean : std::nan("");
  return c;
}

nlohmann::json ResultJson(const FitBenchArgs& a, const Recipe& recipe,
                          const analysis::FitBenchOptions& o, const analysis::FitBenchResult& r,
                          const PeerComparison& c) {
  const ScipyPeerResult& peer = c.peer;
  return {{"recipe", {{"id", recipe.id}, {"version", recipe.version}}},
          {"truth",
           {{"R_ohm", o.truth.r_ohm},
            {"L_h", o.truth.l_h},
            {"Rp_ohm", o.truth.rp_ohm},
            {"f0_hz", o.truth.f0_hz},
            {"Q", o.truth.q}}},
          {"noise", {{"voltage_v_rms", o.voltage_noise_v}, {"current_a_rms", o.current_noise_a}}},
          {"runs", r.runs},
          {"usable_runs", r.usable_runs},
          {"seed", a.seed},
          {"crest_factor", r.excitation.crest_factor},
          {"f0",
           {{"mean_hz", r.f0_mean_hz},
            {"std_hz", r.f0_std_hz},
            {"crb_hz", r.crb_f0_hz},
            {"crb_closed_form_hz", r.crb_f0_closed_form_hz},
            {"std_over_crb", r.std_over_crb},
            {"crb_true_noise_hz", r.crb_true_noise_f0_hz},
            {"std_over_crb_true_noise", r.std_over_crb_true_noise},
            {"bias_over_std", r.bias_over_std}}},
          {"frf_method", analysis::ToString(o.analysis.frf_method)},
          {"simulation", a.sim},
          {"noise_dof", r.noise_dof},
          {"coverage_2sigma", r.coverage_2sigma},
          {"mean_reported_f_sigma_hz", r.mean_reported_f_sigma_hz},
          {"bias",
           {{"ml_hz", r.ml_bias_hz},
            {"peak_pick_hz", r.peak_pick_bias_hz},
            {"peak_pick_std_hz", r.peak_pick_std_hz}}},
          {"time",
           {{"analysis_ms_mean", r.analysis_ms_mean},
            {"analysis_ms_min", r.analysis_ms_min},
            {"scipy_ran", peer.ran},
            {"scipy_message", peer.message},
            {"scipy_version", peer.scipy_version},
            {"scipy_ms_mean", peer.ms_mean},
            {"scipy_over_ours", c.ratio},
            {"scipy_max_f0_diff_over_crb", c.max_diff_sigma}}},
          {"measurement_time",
           {{"target_f0_sigma_hz", o.target_f0_sigma_hz},
            {"averaged_s", r.averaged_time_s},
            {"needed_s", r.time_for_target_s},
            {"check_periods", r.check_periods},
            {"check_predicted_f0_std_hz", r.check_predicted_f0_std_hz},
            {"check_measured_f0_std_hz", r.check_measured_f0_std_hz}}},
          {"chi2_per_dof_mean", r.chi2_per_dof_mean}};
}

// The five figures of analysis/README.md "Measured figures", as text.
void PrintReport(const FitBenchArgs& a, const Recipe& recipe, const analysis::FitBenchOptions& o,
                 const analysis::FitBenchResult& r, const PeerComparison& c) {
  const ScipyPeerResult& peer = c.peer;
  const auto& e = o.excitation;
  std::cout << "eol fit-bench: recipe " << recipe.id << " v" << recipe.version << ": multisine "
            << G(e.f_lo_hz) << "-" << G(e.f_hi_hz) << " Hz at " << G(e.line_spacing_hz)
            << " Hz spacing, " << G(e.sample_rate_hz) << " Hz, " << G(e.peak_v)
            << " V peak (crest factor " << G(r.excitation.crest_factor, 3) << "), "
            << o.transient_periods << " + " << o.periods << " periods\n"
            << "  motor R " << G(o.truth.r_ohm) << " ohm, L " << G(o.truth.l_h) << " H, Rp "
            << G(o.truth.rp_ohm) << " ohm, f0 " << G(o.truth.f0_hz) << " Hz, Q " << G(o.truth.q)
            << "; noise " << G(o.voltage_noise_v) << " V and " << G(o.current_noise_a)
            << " A rms per sample; " << r.usable_runs << "/" << r.runs << " runs, seed " << a.seed
            << "\n"
            << "(1) std(f0) " << G(r.f0_std_hz) << " Hz; Cramer-Rao bound " << G(r.crb_f0_hz)
            << " Hz (closed form " << G(r.crb_f0_closed_form_hz) << " Hz): ratio "
            << G(r.std_over_crb, 3) << " (target <= 1.1)\n"
            << "    estimator " << analysis::ToString(o.analysis.frf_method) << " on " << a.sim
            << " records (noise dof " << G(r.noise_dof, 3) << "); bound with the true noise of all "
            << (o.simulation == analysis::BenchSimulation::kTimeDomain
                    ? o.transient_periods + o.periods
                    : o.periods)
            << " periods " << G(r.crb_true_noise_f0_hz) << " Hz: ratio "
            << G(r.std_over_crb_true_noise, 3) << "\n"
            << "(2) coverage of +-2 f_sigma_hz: " << G(100.0 * r.coverage_2sigma, 3)
            << " % (mean reported f_sigma_hz " << G(r.mean_reported_f_sigma_hz) << ")\n"
            << "(3) bias: ML fit " << G(r.ml_bias_hz) << " Hz (" << G(r.bias_over_std, 2)
            << " std); |Z| peak-picking " << G(r.peak_pick_bias_hz) << " Hz (std "
            << G(r.peak_pick_std_hz) << " Hz), "
            << G(std::abs(r.peak_pick_bias_hz) / r.f0_std_hz, 3) << " ML standard deviations\n"
            << "(4) analysis time per test " << G(r.analysis_ms_mean, 3) << " ms (min "
            << G(r.analysis_ms_min, 3) << " ms)";
  if (peer.ran)
    std::cout << "; SciPy " << peer.scipy_version << " pipeline " << G(peer.ms_mean, 3) << " ms on "
              << peer.f0_hz.size() << " of the same recordings: ratio " << G(c.ratio, 3)
              << " (largest f0 difference " << G(c.max_diff_sigma, 2) << " bounds)\n";
  else
    std::cout << "; SciPy pipeline not run: " << peer.message << "\n";
  std::cout
      << "(5) measurement time for std(f0) = " << G(o.target_f0_sigma_hz)
      << " Hz: " << G(r.time_for_target_s, 3) << " s of averaging (the recipe averages "
      << G(r.averaged_time_s) << " s"
      << (r.time_for_target_s < 1.0 / e.line_spacing_hz
              ? ", and less than one period: the line spacing sets the test time, not the noise"
              : "")
      << "); check at " << r.check_periods << " periods: predicted "
      << G(r.check_predicted_f0_std_hz) << " Hz, Monte Carlo " << G(r.check_measured_f0_std_hz)
      << " Hz\n"
      << "    mean chi2/dof " << G(r.chi2_per_dof_mean, 3) << "\n";
}

int RunFitBench(const FitBenchArgs& a) {
  const Recipe recipe = LoadRecipe(a.recipe);
  analysis::FitBenchOptions o;
  if (!MakeOptions(a, recipe, &o)) return 2;
  analysis::FitBenchResult r;
  {
    Progress progress("fit-bench");
    o.progress = progress.Callback();
    r = analysis::RunFitBench(o);
  }
  if (r.usable_runs < 2) {
    std::cerr << "eol fit-bench: only " << r.usable_runs << " of " << r.runs
              << " runs were usable; first failure: " << r.first_failure << std::endl;
    return 1;
  }
  const PeerComparison peer = ComparePeer(a, o, r);
  if (a.json) {
    std::cout << ResultJson(a, recipe, o, r, peer).dump() << std::endl;
    return 0;
  }
  PrintReport(a, recipe, o, r, peer);
  return 0;
}

}  // namespace

void AddFitBenchCommand(CLI::App& app) {
  auto args = std::make_shared<FitBenchArgs>();
  CLI::App* cmd = app.add_subcommand(
      "fit-bench",
      "Benchmark of the identification engine on simulated measurements of the recipe's motor:\n"
      "std(f0) against the Cramer-Rao bound, coverage of the reported sigma, |Z| peak-picking\n"
      "bias, analysis time per test (and the same pipeline in SciPy, as a ratio), and the\n"
      "measurement time needed for std(f0) = 0.5 Hz.");
  cmd->add_option("--runs", args->runs, "Monte Carlo runs")
      ->capture_default_str()
      ->check(Between(2, 1000000));
  cmd->add_option("--seed", args->seed, "Seed of the noise")->capture_default_str();
  cmd->add_flag("--json", args->json, "Print one JSON object on stdout");
  cmd->add_option("--recipe", args->recipe, "Recipe JSON")->capture_default_str();
  cmd->add_option("--check-runs", args->check_runs, "Runs of the measurement-time check (0: skip)")
      ->capture_default_str()
      ->check(Between(0, 1000000));
  cmd->add_option("--peer-runs", args->peer_runs,
                  "Recordings given to the SciPy pipeline (0: skip it)")
      ->capture_default_str()
      ->check(Between(0, 10000));
  cmd->add_option("--python", args->python, "Python with SciPy")->capture_default_str();
  cmd->add_option("--script", args->script, "The SciPy pipeline")->capture_default_str();
  cmd->add_option("--frf-method", args->frf_method,
                  "discard_transient or transient_lpm (default: the recipe's)");
  cmd->add_option("--sim", args->sim,
                  "steady_state (no transient) or time_domain (from rest, transient included)")
      ->capture_default_str();
  cmd->add_option("--series-ohm", args->series_ohm,
                  "time_domain: amplifier output + shunt in series with the motor")
      ->capture_default_str();
  cmd->add_option("--line-spacing-hz", args->line_spacing_hz, "Override the recipe's spacing");
  cmd->add_option("--periods", args->periods, "Override the recipe's averaged periods");
  cmd->add_option("--transient-periods", args->transient_periods,
                  "Override the recipe's transient periods");
  cmd->add_option("--lpm-degree", args->lpm_degree, "transient_lpm: polynomial degree");
  cmd->add_option("--lpm-half-width", args->lpm_half_width,
                  "transient_lpm: non-excited bins on each side");
  cmd->callback([args] { RunGuarded("fit-bench", [&] { return RunFitBench(*args); }); });
}

}  // namespace eol::station::cli
