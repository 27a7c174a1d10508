// Benchmark of the identification engine on simulated measurements (`eol fit-bench`).
//
// One run is the recipe's measurement of a known motor: the excitation period repeated
// transient_periods + periods times, the motor's periodic steady-state current
// (analysis/sim/steady_state.h), white Gaussian noise added to both recorded channels (the
// simulated DAQ's model), then EstimatePeriodicFrf and FitMotionalResonance exactly as the
// station runs them. Over many seeded runs it measures:
//   (1) std(f0_hat) against the Cramer-Rao bound (cramer_rao.h) evaluated at the truth with
//       the per-line sigma the estimator reports (root-mean-square over the runs);
//   (2) coverage: the share of runs with |f0_hat - f0| <= 2 f_sigma_hz (~95 % when honest);
//   (3) the bias of |Z| peak-picking (the local maximum of |Z| with the deepest dip over the
//       next 20 lines, refined by a parabola through it and its two neighbours) next to the
//       bias of the ML fit (analysis/README.md 2: |Z| peaks below f0, at 387.6 Hz for the
//       reference);
//   (4) the analysis time per test (estimator + fit);
//   (5) the measurement time for a target std(f0). The per-line sigma of a periodic
//       measurement falls as 1/sqrt(T_m) (analysis/README.md 3: sigma_G^2 = 2 S_v / (A_k^2 T_m)),
//       and the bound is proportional to sigma, so
//           T_needed = T_m (crb_f0(T_m) / target)^2,   T_m = periods / line_spacing_hz;
//       checked against a second Monte Carlo at the shortest averaging the estimator accepts.
// Pure computation: no files, no processes (the SciPy comparison is run by the station).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/impedance_analysis.h"
#include "analysis/model/motor_model.h"
#include "analysis/progress.h"
#include "analysis/signal/multisine.h"
#include "analysis/signal/recording.h"

namespace eol::analysis {

// A voltage-driven periodic measurement of `motor`: `periods` repetitions of the excitation's
// period (the first ones are where the station's transient periods go; the response is the
// steady state throughout), with N(0, voltage_noise_v^2) and N(0, current_noise_a^2) added
// per sample. Full scales are left 0 (no clipping check). Deterministic in seed.
Recording SimulatePeriodicRecording(const MotionalImpedance& motor, const Excitation& excitation,
                                    std::size_t periods, double voltage_noise_v,
                                    double current_noise_a, std::uint64_t seed);

// The same measurement simulated FROM REST in the time domain (analysis/sim/time_domain.h):
// the amplifier plays `periods` periods into a one-inertia clamped motor with this
// impedance (J_r = 1e-4 kg m^2; Z does not depend on it) through series_ohm (amplifier
// output + shunt), so both recorded channels (motor voltage and current) carry the start
// transient. Noise as above. Deterministic in seed.
Recording SimulateRecordingFromRest(const MotionalImpedance& motor, const Excitation& excitation,
                                    std::size_t periods, double series_ohm, double voltage_noise_v,
                                    double current_noise_a, std::uint64_t seed);

// Per-line complex std of Z from the channels' true sample noise alone, for a record of
// `periods` periods analysed as one (no price for a transient): analysis/README.md 3 with the line
// amplitudes of the motor voltage and current through series_ohm,
//   sigma_k^2 = |Z_k|^2 (4 s_u^2 / (P n |U_k|^2) + 4 s_i^2 / (P n |I_k|^2)).
std::vector<double> TrueNoiseLineSigma(const MotionalImpedance& motor, const Excitation& excitation,
                                       std::size_t periods, double series_ohm,
                                       double voltage_noise_v, double current_noise_a);

// How fit-bench simulates the recordings.
enum class BenchSimulation {
  kSteadyState,  // SimulatePeriodicRecording: no transient (the first periods are steady too)
  kTimeDomain,   // SimulateRecordingFromRest: the start transient is in the record
};

struct FitBenchOptions {
  BenchSimulation simulation = BenchSimulation::kSteadyState;
  double series_ohm = 0.0;  // kTimeDomain: amplifier output + shunt resistance
  MotionalImpedance truth{0.5, 2.0e-3, 0.51, 390.0, 50.0};
  MultisineOptions excitation;        // the recipe's
  std::size_t periods = 4;            // averaged
  std::size_t transient_periods = 1;  // played first and dropped
  double voltage_noise_v = 2.0e-3;    // rms per sample (the simulated DAQ)
  double current_noise_a = 1.0e-3;
  ImpedanceAnalysisOptions analysis;  // the recipe's
  int runs = 500;
  std::uint64_t seed = 1;
  double target_f0_sigma_hz = 0.5;
  int check_runs = 200;  // runs of the measurement-time check (0: skip it)
  // The first keep_recordings recordings are returned (for an external peer).
  std::size_t keep_recordings = 0;
  // Sees each finished run: phase "runs", then "check runs" (analysis/progress.h).
  ProgressCallback progress;

  bool IsValid(std::string* why) const;
};

struct FitBenchResult {
  int runs = 0;
  int usable_runs = 0;
  std::string first_failure;  // message of the first unusable run, if any
  double f0_true_hz = 0.0;
  // (1)
  double f0_mean_hz = 0.0;
  double f0_std_hz = 0.0;
  double crb_f0_hz = 0.0;              // at the truth, rms of the reported line sigmas
  double crb_f0_closed_form_hz = 0.0;  // analysis/README.md 4 closed form, the line sigma at f0
  double std_over_crb = 0.0;
  // The bound with the channels' true noise over every recorded period (TrueNoiseLineSigma:
  // what an estimator that wasted nothing would have) and the ratio to it.
  double crb_true_noise_f0_hz = 0.0;
  double std_over_crb_true_noise = 0.0;
  double bias_over_std = 0.0;  // ml_bias_hz / f0_std_hz
  double noise_dof = 0.0;      // FrfSummary::noise_dof of the first usable run
  // (2)
  double mean_reported_f_sigma_hz = 0.0;
  double coverage_2sigma = 0.0;
  // (3)
  double ml_bias_hz = 0.0;         // mean(f0_hat) - f0
  double peak_pick_bias_hz = 0.0;  // mean(f_peak) - f0
  double peak_pick_std_hz = 0.0;
  // (4)
  double analysis_ms_mean = 0.0;
  double analysis_ms_min = 0.0;
  // (5)
  double averaged_time_s = 0.0;            // T_m of the recipe
  double time_for_target_s = 0.0;          // T_needed
  std::size_t check_periods = 0;           // averaged periods of the check run
  double check_predicted_f0_std_hz = 0.0;  // CRB at check_periods
  double check_measured_f0_std_hz = 0.0;   // Monte Carlo at check_periods (NaN: skipped)
  double chi2_per_dof_mean = 0.0;

  std::vector<Recording> kept;         // the first keep_recordings recordings
  std::vector<double> kept_f0_hat_hz;  // and our f0 on each (NaN when not usable)
  Excitation excitation;
};

// Throws std::invalid_argument when !options.IsValid(). Single-threaded, deterministic in seed.
FitBenchResult RunFitBench(const FitBenchOptions& options);

}  // namespace eol::analysis
