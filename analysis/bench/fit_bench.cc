#include "analysis/bench/fit_bench.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>

#include "analysis/fit/cramer_rao.h"
#include "analysis/model/pmsm_network.h"
#include "analysis/model/torsional_chain.h"
#include "analysis/signal/fft.h"
#include "analysis/sim/steady_state.h"
#include "analysis/sim/time_domain.h"

namespace eol::analysis {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

double Mean(const std::vector<double>& v) {
  double s = 0.0;
  for (double x : v) s += x;
  return v.empty() ? kNaN : s / static_cast<double>(v.size());
}

double StdDev(const std::vector<double>& v) {
  if (v.size() < 2) return kNaN;
  const double m = Mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / static_cast<double>(v.size() - 1));
}

// Peak-picking as a simple tester would: |Z| rises with w L, so the motional peak is a local
// maximum, the one with the deepest dip over the following kDipLines lines; refined by a
// parabola through it and its two neighbours.
constexpr std::size_t kDipLines = 20;
double PeakPickHz(const Frf& z, double f_lo_hz, double f_hi_hz) {
  std::size_t best = z.size();
  double best_drop = 0.0;
  for (std::size_t k = 1; k + 1 < z.size(); ++k) {
    if (z.freq_hz[k] < f_lo_hz || z.freq_hz[k] > f_hi_hz) continue;
    const double m = std::abs(z.value[k]);
    if (!(m > std::abs(z.value[k - 1]) && m >= std::abs(z.value[k + 1]))) continue;
    double low = m;
    for (std::size_t j = k + 1; j < std::min(z.size(), k + 1 + kDipLines); ++j)
      low = std::min(low, std::abs(z.value[j]));
    if (m - low > best_drop) {
      best_drop = m - low;
      best = k;
    }
  }
  if (best == z.size()) return kNaN;
  const double a = std::abs(z.value[best - 1]), b = std::abs(z.value[best]);
  const double c = std::abs(z.value[best + 1]);
  const double den = a - 2.0 * b + c;
  const double offset = den != 0.0 ? 0.5 * (a - c) / den : 0.0;
  const double df = 0.5 * (z.freq_hz[best + 1] - z.freq_hz[best - 1]);
  return z.freq_hz[best] + std::clamp(offset, -0.5, 0.5) * df;
}

struct MonteCarlo {
  std::vector<double> f0_hat, f_sigma, peak, analysis_ms, chi2_per_dof;
  std::vector<double> sigma2_sum;  // per line, sum over usable runs of sigma^2
  std::vector<double> freq_hz;
  double noise_dof = 0.0;
  int usable = 0;
  std::string first_failure;
};

MonteCarlo RunMonteCarlo(const FitBenchOptions& o, const Excitation& e, std::size_t periods,
                         int runs, std::uint64_t seed, FitBenchResult* keep,
                         std::string_view phase) {
  MonteCarlo mc;
  const double f_lo = o.analysis.fit.f0_min_hz > 0.0 ? o.analysis.fit.f0_min_hz : 0.0;
  const double f_hi = o.analysis.fit.f0_max_hz > 0.0 ? o.analysis.fit.f0_max_hz
                                                     : std::numeric_limits<double>::infinity();
  for (int r = 0; r < runs; ++r) {
    if (o.progress) o.progress(phase, r, runs);
    const std::uint64_t run_seed = seed + 7919ULL * static_cast<std::uint64_t>(r);
    const Recording rec =
        o.simulation == BenchSimulation::kTimeDomain
            ? SimulateRecordingFromRest(o.truth, e, o.transient_periods + periods, o.series_ohm,
                                        o.voltage_noise_v, o.current_noise_a, run_seed)
            : SimulatePeriodicRecording(o.truth, e, o.transient_periods + periods,
                                        o.voltage_noise_v, o.current_noise_a, run_seed);
    const auto t0 = std::chrono::steady_clock::now();
    const ImpedanceAnalysis a = AnalyzeRecording(rec, e.lines, o.analysis);
    const auto t1 = std::chrono::steady_clock::now();
    const bool kept = keep && keep->kept.size() < o.keep_recordings;
    if (kept) keep->kept.push_back(rec);
    if (!a.usable) {
      if (mc.first_failure.empty()) mc.first_failure = a.message;
      if (kept) keep->kept_f0_hat_hz.push_back(kNaN);
      continue;
    }
    const FittedParameter* f0 = a.fit.Find("f0_hz");
    if (kept) keep->kept_f0_hat_hz.push_back(f0->value);
    ++mc.usable;
    mc.analysis_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    mc.f0_hat.push_back(f0->value);
    mc.f_sigma.push_back(f0->sigma);
    mc.chi2_per_dof.push_back(a.fit.chi2_per_dof);
    mc.peak.push_back(PeakPickHz(a.frf.frf, f_lo, f_hi));
    const Frf& z = a.frf.frf;
    if (mc.freq_hz.empty()) {
      mc.noise_dof = a.frf.noise_dof;
      mc.freq_hz = z.freq_hz;
      mc.sigma2_sum.assign(z.size(), 0.0);
    }
    if (z.freq_hz == mc.freq_hz)
      for (std::size_t k = 0; k < z.size(); ++k) mc.sigma2_sum[k] += z.sigma[k] * z.sigma[k];
  }
  if (o.progress) o.progress(phase, runs, runs);
  return mc;
}

// The bound at the truth with the rms of the reported line sigmas.
CramerRaoBound BoundOf(const MotionalImpedance& truth, const MonteCarlo& mc) {
  std::vector<double> sigma(mc.sigma2_sum.size());
  for (std::size_t k = 0; k < sigma.size(); ++k)
    sigma[k] = std::sqrt(mc.sigma2_sum[k] / static_cast<double>(mc.usable));
  return ComputeCramerRaoBound(truth, mc.freq_hz, sigma);
}

}  // namespace

Recording SimulatePeriodicRecording(const MotionalImpedance& motor, const Excitation& e,
                                    std::size_t periods, double voltage_noise_v,
                                    double current_noise_a, std::uint64_t seed) {
  const std::vector<double> i_period =
      SteadyStateCurrent([&](double f) { return motor.At(f); }, e.period_v, e.sample_rate_hz);
  Recording rec;
  rec.sample_rate_hz = e.sample_rate_hz;
  rec.period_samples = e.period_samples;
  rec.voltage_v = e.Repeat(periods);
  rec.current_a.resize(rec.voltage_v.size());
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> vn(0.0, voltage_noise_v > 0.0 ? voltage_noise_v : 1.0);
  std::normal_distribution<double> in(0.0, current_noise_a > 0.0 ? current_noise_a : 1.0);
  for (std::size_t t = 0; t < rec.voltage_v.size(); ++t) {
    rec.current_a[t] = i_period[t % e.period_samples];
    if (voltage_noise_v > 0.0) rec.voltage_v[t] += vn(rng);
    if (current_noise_a > 0.0) rec.current_a[t] += in(rng);
  }
  return rec;
}

Recording SimulateRecordingFromRest(const MotionalImpedance& motor, const Excitation& e,
                                    std::size_t periods, double series_ohm, double voltage_noise_v,
                                    double current_noise_a, std::uint64_t seed) {
  const PmsmParams p = FromMotional(motor, 1.0e-4);
  ClampedMotor m;
  m.r_ohm = p.r_ohm;
  m.l_h = p.l_h;
  m.transmission_nm_per_a = p.transmission_nm_per_a;
  const int rotor = m.chain.AddInertia("rotor", p.inertia_kg_m2);
  m.chain.AddElement("spring", rotor, kGround, 1.0 / p.compliance_rad_per_nm,
                     p.damping_nms_per_rad);
  m.chain.SetTorqueWeight(rotor, 1.0);
  TimeDomainOptions t;
  t.sample_rate_hz = e.sample_rate_hz;
  t.circuit.amplifier_output_ohm = series_ohm;
  return SimulateRecording(m, t, e.Repeat(periods), e.period_samples,
                           ChannelNoise{voltage_noise_v, current_noise_a, seed});
}

std::vector<double> TrueNoiseLineSigma(const MotionalImpedance& motor, const Excitation& e,
                                       std::size_t periods, double series_ohm,
                                       double voltage_noise_v, double current_noise_a) {
  const std::size_t n = e.period_samples;
  const std::vector<std::complex<double>> bins = RealFft(n).Forward(e.period_v.data());
  const double total = static_cast<double>(periods * n);
  std::vector<double> sigma;
  for (std::size_t k : e.lines) {
    const std::complex<double> u_amp = bins[k] * (2.0 / static_cast<double>(n));
    const std::complex<double> z = motor.At(static_cast<double>(k) * e.line_spacing_hz);
    const std::complex<double> i = u_amp / (z + series_ohm);
    const std::complex<double> u = i * z;
    const double var_u = 4.0 * voltage_noise_v * voltage_noise_v / total;
    const double var_i = 4.0 * current_noise_a * current_noise_a / total;
    sigma.push_back(std::abs(z) * std::sqrt(var_u / std::norm(u) + var_i / std::norm(i)));
  }
  return sigma;
}

bool FitBenchOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(truth.r_ohm > 0.0 && truth.l_h > 0.0 && truth.rp_ohm > 0.0 && truth.f0_hz > 0.0 &&
        truth.q > 0.0))
    return fail("truth: every parameter must be positive");
  std::string e;
  if (!excitation.IsValid(&e)) return fail("excitation: " + e);
  if (!analysis.frf.IsValid(&e)) return fail("analysis.frf: " + e);
  if (!analysis.fit.IsValid(&e)) return fail("analysis.fit: " + e);
  if (analysis.frf_method == FrfMethod::kTransientLpm) {
    if (!analysis.lpm.IsValid(&e)) return fail("analysis.lpm: " + e);
    if (transient_periods + periods < 2)
      return fail("transient_periods + periods must be at least 2");
  } else {
    if (periods < analysis.frf.min_periods)
      return fail("periods must be at least analysis.frf.min_periods");
    if (transient_periods < analysis.frf.transient_periods)
      return fail("transient_periods must be at least analysis.frf.transient_periods");
  }
  if (!(series_ohm >= 0.0 && std::isfinite(series_ohm)))
    return fail("series_ohm must be finite and not negative");
  if (!(voltage_noise_v > 0.0 && current_noise_a > 0.0))
    return fail("noise levels must be positive");
  if (runs < 2) return fail("runs must be at least 2");
  if (check_runs < 0) return fail("check_runs must not be negative");
  if (!(target_f0_sigma_hz > 0.0)) return fail("target_f0_sigma_hz must be positive");
  return true;
}

FitBenchResult RunFitBench(const FitBenchOptions& o) {
  std::string why;
  if (!o.IsValid(&why)) throw std::invalid_argument("fit bench: " + why);
  FitBenchResult res;
  res.excitation = DesignMultisine(o.excitation);
  res.runs = o.runs;
  res.f0_true_hz = o.truth.f0_hz;
  const MonteCarlo mc = RunMonteCarlo(o, res.excitation, o.periods, o.runs, o.seed, &res, "runs");
  res.usable_runs = mc.usable;
  res.first_failure = mc.first_failure;
  if (mc.usable < 2) return res;

  res.f0_mean_hz = Mean(mc.f0_hat);
  res.f0_std_hz = StdDev(mc.f0_hat);
  const CramerRaoBound crb = BoundOf(o.truth, mc);
  res.crb_f0_hz = crb.valid ? crb.Std(kParamF0) : kNaN;
  // Closed form with the line sigma nearest f0 (sigma grows with |Z| across the band).
  std::size_t at_f0 = 0;
  for (std::size_t k = 0; k < mc.freq_hz.size(); ++k)
    if (std::abs(mc.freq_hz[k] - o.truth.f0_hz) < std::abs(mc.freq_hz[at_f0] - o.truth.f0_hz))
      at_f0 = k;
  res.crb_f0_closed_form_hz = CramerRaoF0ClosedFormHz(o.truth.f0_hz, o.truth.q, o.truth.rp_ohm,
                                                      o.excitation.line_spacing_hz,
                                                      std::sqrt(mc.sigma2_sum[at_f0] / mc.usable));
  res.std_over_crb = res.f0_std_hz / res.crb_f0_hz;
  {
    // From rest every recorded period counts for the ideal estimator (the short record's
    // bound); the steady-state recording keeps its meaning of `periods` averaged.
    const std::size_t recorded =
        o.simulation == BenchSimulation::kTimeDomain ? o.transient_periods + o.periods : o.periods;
    const CramerRaoBound ideal =
        ComputeCramerRaoBound(o.truth, res.excitation.LineFrequenciesHz(),
                              TrueNoiseLineSigma(o.truth, res.excitation, recorded, o.series_ohm,
                                                 o.voltage_noise_v, o.current_noise_a));
    res.crb_true_noise_f0_hz = ideal.valid ? ideal.Std(kParamF0) : kNaN;
    res.std_over_crb_true_noise = res.f0_std_hz / res.crb_true_noise_f0_hz;
  }
  res.noise_dof = mc.noise_dof;

  int covered = 0;
  for (std::size_t r = 0; r < mc.f0_hat.size(); ++r)
    if (std::abs(mc.f0_hat[r] - o.truth.f0_hz) <= 2.0 * mc.f_sigma[r]) ++covered;
  res.coverage_2sigma = static_cast<double>(covered) / static_cast<double>(mc.usable);
  res.mean_reported_f_sigma_hz = Mean(mc.f_sigma);
  res.ml_bias_hz = res.f0_mean_hz - o.truth.f0_hz;
  res.bias_over_std = res.ml_bias_hz / res.f0_std_hz;
  res.peak_pick_bias_hz = Mean(mc.peak) - o.truth.f0_hz;
  res.peak_pick_std_hz = StdDev(mc.peak);
  res.analysis_ms_mean = Mean(mc.analysis_ms);
  res.analysis_ms_min = *std::min_element(mc.analysis_ms.begin(), mc.analysis_ms.end());
  res.chi2_per_dof_mean = Mean(mc.chi2_per_dof);

  res.averaged_time_s = static_cast<double>(o.periods) / o.excitation.line_spacing_hz;
  res.time_for_target_s = res.averaged_time_s * std::pow(res.crb_f0_hz / o.target_f0_sigma_hz, 2.0);
  res.check_periods = o.analysis.frf.min_periods;
  res.check_predicted_f0_std_hz = res.crb_f0_hz * std::sqrt(static_cast<double>(o.periods) /
                                                            static_cast<double>(res.check_periods));
  res.check_measured_f0_std_hz = kNaN;
  if (o.check_runs >= 2) {
    const MonteCarlo check = RunMonteCarlo(o, res.excitation, res.check_periods, o.check_runs,
                                           o.seed + 1000003ULL, nullptr, "check runs");
    res.check_measured_f0_std_hz = check.usable >= 2 ? StdDev(check.f0_hat) : kNaN;
  }
  return res;
}

}  // namespace eol::analysis
