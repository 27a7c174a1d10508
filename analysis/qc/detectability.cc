#include "analysis/qc/detectability.h"

#include <cmath>
#include <cstdio>

#include "analysis/impedance_analysis.h"
#include "analysis/qc/line_measurement.h"
#include "analysis/qc/line_population.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/qc/tolerance.h"

namespace eol::analysis {
namespace {

const std::string kChi2(names::kFitChi2PerDof);

struct Expected {
  Frf frf;
  ImpedanceAnalysis analysis;
};

struct Context {
  const DetectabilityOptions& o;
  LineMeasurementSetup setup;

  Expected Evaluate(const RotorChainParams& p) const {
    ClampedMotor motor;
    motor.r_ohm = o.r_ohm;
    motor.l_h = o.l_h;
    motor.transmission_nm_per_a = o.transmission_nm_per_a;
    motor.chain = BuildRotorChain(p);
    Expected e;
    e.frf = MeasureLineUnit(setup, ModalImpedance(motor, setup.freq_hz), 0, false);
    // Detectability reads the fit, never the second-mode drop: skip its two-mode fit (about
    // 35 ms a curve, hundreds of curves: /api/detectability took 20 s with it).
    ResonanceFitOptions fit = o.fit;
    fit.second_mode_test = false;
    e.analysis = AnalyzeImpedance(e.frf, fit);
    return e;
  }
};

std::string Fmt(const char* format, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

RotorChainParams WithFixtureScale(const RotorChainParams& p, double scale) {
  RotorChainParams q = p;
  if (!std::isfinite(scale)) {
    q.fixture.reset();
  } else {
    q.fixture->stiffness_nm_per_rad *= scale;
    q.fixture->damping_nms_per_rad *= scale;
  }
  return q;
}

// Separations of a defect against the good unit. p_scale multiplies the averaged periods
// (noise variance / p_scale, chi2_0 x p_scale); spread_scale_f0 rescales the f0 spread.
std::vector<MeasurementSeparation> Separate(const DetectabilityOptions& o, const Expected& good,
                                            const Expected& defect, double p_scale,
                                            double spread_scale_f0, double spread_scale = 1.0) {
  std::vector<MeasurementSeparation> out;
  const int dof = good.analysis.fit.dof;
  for (const auto& [name, g] : good.analysis.values) {
    const auto d = defect.analysis.values.find(name);
    if (d == defect.analysis.values.end()) continue;
    MeasurementSeparation m;
    m.name = name;
    const auto given = o.unit_spread.find(name);
    if (name == kChi2) {
      m.good = 1.0 + good.analysis.fit.chi2 * p_scale / dof;
      m.defect = 1.0 + defect.analysis.fit.chi2 * p_scale / dof;
      m.sigma = std::sqrt(2.0 / dof);
      m.spread = given != o.unit_spread.end() ? given->second * spread_scale : 0.0;
    } else {
      if (given == o.unit_spread.end()) continue;
      m.good = g.value;
      m.defect = d->second.value;
      m.sigma = g.sigma / std::sqrt(p_scale);
      m.spread = given->second * spread_scale *
                 (name == std::string(names::kResonanceFHz) ? spread_scale_f0 : 1.0);
    }
    const double total = std::hypot(m.spread, m.sigma);
    m.separation = total > 0.0 ? std::abs(m.defect - m.good) / total : 0.0;
    m.limit_is_lo = m.defect < m.good;
    m.recommended_limit = m.good + (m.limit_is_lo ? -1.0 : 1.0) * o.required_sigmas * total;
    m.miss_probability =
        total > 0.0 ? (m.limit_is_lo ? 1.0 - NormalCdf((m.recommended_limit - m.defect) / total)
                                     : NormalCdf((m.recommended_limit - m.defect) / total))
                    : 0.0;
    out.push_back(m);
  }
  return out;
}

const MeasurementSeparation* Best(const std::vector<MeasurementSeparation>& v) {
  const MeasurementSeparation* best = nullptr;
  for (const auto& m : v)
    if (!best || m.separation > best->separation) best = &m;
  return best;
}

}  // namespace

bool DetectabilityOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  std::string w;
  if (!rotor.IsValid(&w)) return fail("rotor: " + w);
  if (!rotor.fixture) return fail("rotor: the fixture must be set (the station's clamp)");
  if (!(r_ohm > 0.0 && l_h > 0.0 && transmission_nm_per_a > 0.0))
    return fail("r_ohm, l_h and transmission_nm_per_a must be positive");
  if (!excitation.IsValid(&w)) return fail("excitation: " + w);
  if (periods < 1) return fail("periods must be at least 1");
  if (!(voltage_noise_v > 0.0 && current_noise_a > 0.0))
    return fail("channel noise must be positive");
  if (!fit.IsValid(&w)) return fail("fit: " + w);
  for (const auto& [name, s] : unit_spread)
    if (!(s >= 0.0 && std::isfinite(s))) return fail("unit spread of " + name + " must be >= 0");
  for (double f : bond_fractions)
    if (!(f > 0.0 && f <= 1.0)) return fail("bond fractions must be in (0, 1]");
  for (double a : pod_losses)
    if (!(a > 0.0 && a < 1.0)) return fail("pod losses must be in (0, 1)");
  if (!(required_sigmas > 0.0)) return fail("required_sigmas must be positive");
  if (spread_units < 0) return fail("spread_units must not be negative");
  if (!(pod_confidence > 0.5 && pod_confidence < 1.0))
    return fail("pod_confidence must be in (0.5, 1)");
  return true;
}

namespace {

// The clamp stiffnesses tried, as multiples of the present one (INFINITY: a rigid shaft end).
const std::vector<double> kClampScales = {1.25, 1.5, 2, 3, 5, 10, 20, 50, 100, INFINITY};

// The stiffer clamp that separates a class the present fixture does not (or the rigid end's
// separation when none does).
std::string StifferClampRemedy(const Context& ctx, const DetectabilityOptions& o,
                               const DetectabilitySummary& s, const RotorChainParams& params,
                               const std::vector<Expected>& good_clamped) {
  std::string clamp = "a stiffer clamp does not separate it: even a rigid shaft end gives ";
  double rigid_sep = 0.0;
  for (std::size_t i = 0; i < kClampScales.size(); ++i) {
    const Expected& g = good_clamped[i];
    if (!g.analysis.usable) continue;
    const Expected dc = ctx.Evaluate(WithFixtureScale(params, kClampScales[i]));
    if (!dc.analysis.usable) continue;
    const double f0_ratio = g.analysis.fit.Find("f0_hz")->value / s.f0_good_hz;
    const auto seps = Separate(o, g, dc, 1.0, f0_ratio);
    const MeasurementSeparation* b = Best(seps);
    const double sep = b ? b->separation : 0.0;
    rigid_sep = sep;
    if (sep >= o.required_sigmas) {
      clamp = std::isfinite(kClampScales[i])
                  ? "stiffer clamp: k_fixture >= " +
                        Fmt("%.0f", kClampScales[i] * s.k_fixture_nm_per_rad) + " N m/rad (" +
                        Fmt("%.3g", kClampScales[i]) + " x the present " +
                        Fmt("%.0f", s.k_fixture_nm_per_rad) + ") separates it by " +
                        Fmt("%.1f", sep) + " sigma in " + b->name
                  : "stiffer clamp: only a rigid shaft end (beyond 100 x the present " +
                        Fmt("%.0f", s.k_fixture_nm_per_rad) + " N m/rad) separates it (" +
                        Fmt("%.1f", sep) + " sigma in " + b->name + ")";
      rigid_sep = -1.0;
      break;
    }
  }
  if (rigid_sep >= 0.0) clamp += Fmt("%.1f", rigid_sep) + " sigma";
  return clamp;
}

// More averaged periods (or a phase pair of stronger coupling) that separate a class, or why
// none does.
void AddLongerMeasurementRemedies(const DetectabilityOptions& o, const Expected& good,
                                  const Expected& d, DefectPrediction* pp) {
  DefectPrediction& p = *pp;
  double p_scale = 0.0;
  const MeasurementSeparation* via = nullptr;
  std::vector<MeasurementSeparation> seps;
  for (double f = 1.25; f <= 4096.0; f *= 1.25) {
    seps = Separate(o, good, d, f, 1.0);
    via = Best(seps);
    if (via && via->separation >= o.required_sigmas) {
      p_scale = f;
      break;
    }
  }
  if (p_scale > 0.0) {
    const double periods = std::ceil(p_scale * static_cast<double>(o.periods));
    p.remedies.push_back(std::string(periods > 100.0 ? "impractical: " : "") +
                         "longer measurement: " + Fmt("%.0f", periods) + " averaged periods (now " +
                         std::to_string(o.periods) + "; " +
                         Fmt("%.1f", (periods + static_cast<double>(o.transient_periods)) /
                                         o.excitation.line_spacing_hz) +
                         " s of excitation) separate it by " + Fmt("%.1f", via->separation) +
                         " sigma in " + via->name);
    p.remedies.push_back(
        "another phase pair: one whose coupling T at the clamped rotor "
        "position is " +
        Fmt("%.2g", std::sqrt(p_scale)) +
        " x the present one does the same (Rp ~ T^2: the noise-limited "
        "separation grows like the periods)");
  } else {
    p.remedies.push_back(
        "longer measurement or another phase pair cannot separate it: the good units' own "
        "spread, not the measurement noise, hides it (even 4096 x the periods)");
  }
}

// One defect class against the good rotor: its fit, its best measurement's separation, and
// the remedies when that falls short of the required sigmas.
DefectPrediction PredictClass(const Context& ctx, const DetectabilityOptions& o,
                              const DetectabilitySummary& s, const Expected& good,
                              const std::vector<Expected>& good_clamped, const std::string& name,
                              const RotorChainParams& params) {
  DefectPrediction p;
  p.defect = name;
  const Expected d = ctx.Evaluate(params);
  p.fit_usable = d.analysis.usable;
  p.fit_message = d.analysis.fit.message;
  for (std::size_t k = 0; k < d.frf.size(); ++k)
    p.curve_separation += 2.0 * std::norm(d.frf.value[k] - good.frf.value[k]) /
                          (good.frf.sigma[k] * good.frf.sigma[k]);
  p.curve_separation = std::sqrt(p.curve_separation);
  if (!p.fit_usable) {
    p.separable = true;
    p.best = "fit";
    p.remedies.push_back(
        "the station's fit finds no resonance for this class: it ends ERROR "
        "(never PASS) and is retested; no limit needed");
    return p;
  }
  p.f0_hz = d.analysis.fit.Find("f0_hz")->value;
  p.q = d.analysis.fit.Find("Q")->value;
  p.rp_ohm = d.analysis.fit.Find("Rp_ohm")->value;
  p.chi2_per_dof = 1.0 + d.analysis.fit.chi2 / s.dof;
  p.measurements = Separate(o, good, d, 1.0, 1.0);
  if (const MeasurementSeparation* b = Best(p.measurements)) {
    p.best = b->name;
    p.best_separation = b->separation;
  }
  p.separable = p.best_separation >= o.required_sigmas;
  if (!p.separable) {
    p.remedies.push_back(StifferClampRemedy(ctx, o, s, params, good_clamped));
    AddLongerMeasurementRemedies(o, good, d, &p);
  }
  return p;
}

// detectability.h: the spread's upper confidence bound, s sqrt(nu / chi2_nu(1 - gamma)); NaN
// without spread units.
double UpperSpread(const DetectabilityOptions& o) {
  if (o.spread_units < 2) return std::nan("");
  const double nu = o.spread_units - 1;
  double lo = 0.0, hi = nu;  // chi2 quantile at 1 - gamma: upper tail gamma
  while (ChiSquareUpperTail(hi, nu) > 1.0 - o.pod_confidence) hi *= 2.0;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareUpperTail(mid, nu) > o.pod_confidence ? lo : hi) = mid;
  }
  return std::sqrt(nu / (0.5 * (lo + hi)));
}

// a90 on a grid of (loss, POD): POD stays >= 0.9 from there on; NaN when it ends below.
double StaysAbove(const std::vector<ModelPodPoint>& pts, double ModelPodPoint::*pod) {
  for (std::size_t k = pts.size(); k-- > 0;) {
    if (pts[k].*pod < 0.9) {
      if (k + 1 == pts.size()) return std::nan("");
      const ModelPodPoint &lo = pts[k], &up = pts[k + 1];
      return lo.loss + (0.9 - lo.*pod) / (up.*pod - lo.*pod) * (up.loss - lo.loss);
    }
  }
  return pts.empty() ? std::nan("") : pts.front().loss;
}

// The model's POD over o.pod_losses for one soft magnet or all of them ("one_magnet",
// "all_magnets"), with its a90 and, given spread units, a90/95.
ModelPod PredictPod(const Context& ctx, const DetectabilityOptions& o, const Expected& good,
                    const char* which, double upper_spread) {
  ModelPod pod;
  pod.name = which;
  for (double a : o.pod_losses) {
    RotorChainParams p = o.rotor;
    p.bond_poor = {o.rotor.bond.stiffness_nm_per_rad * (1.0 - a),
                   o.rotor.bond.damping_nms_per_rad * (1.0 - a)};
    p.soft_magnets.clear();
    const int soft = std::string(which) == "one_magnet" ? 1 : p.magnets;
    for (int i = 0; i < soft; ++i) p.soft_magnets.push_back(i);
    const Expected d = ctx.Evaluate(p);
    ModelPodPoint pt;
    pt.loss = a;
    pt.pod_lower = std::nan("");
    if (!d.analysis.usable) {
      pt.pod = 1.0;
      pt.pod_lower = std::isnan(upper_spread) ? pt.pod_lower : 1.0;
      pt.best = "fit (ERROR)";
    } else {
      pt.f0_hz = d.analysis.fit.Find("f0_hz")->value;
      for (const auto& m : Separate(o, good, d, 1.0, 1.0))
        if (1.0 - m.miss_probability > pt.pod) {
          pt.pod = 1.0 - m.miss_probability;
          pt.best = m.name;
        }
      if (!std::isnan(upper_spread)) {
        pt.pod_lower = 0.0;
        for (const auto& m : Separate(o, good, d, 1.0, 1.0, upper_spread))
          pt.pod_lower = std::max(pt.pod_lower, 1.0 - m.miss_probability);
      }
    }
    pod.points.push_back(pt);
  }
  // MIL-HDBK-1823A's reading: a POD that dips again (one soft magnet whose local mode meets
  // the rotor's) moves a90 past the dip.
  pod.a90 = StaysAbove(pod.points, &ModelPodPoint::pod);
  pod.a90_95 =
      std::isnan(upper_spread) ? std::nan("") : StaysAbove(pod.points, &ModelPodPoint::pod_lower);
  return pod;
}

}  // namespace

DetectabilitySummary PredictDetectability(const DetectabilityOptions& o) {
  DetectabilitySummary s;
  std::string why;
  if (!o.IsValid(&why)) {
    s.message = "detectability options: " + why;
    return s;
  }
  const Context ctx{
      o, MakeLineMeasurement(o.excitation, o.periods, o.voltage_noise_v, o.current_noise_a)};
  s.k_fixture_nm_per_rad = o.rotor.fixture->stiffness_nm_per_rad;
  const Expected good = ctx.Evaluate(o.rotor);
  if (!good.analysis.usable) {
    s.message = "the good rotor in this fixture gives no usable fit: " + good.analysis.message;
    return s;
  }
  s.dof = good.analysis.fit.dof;
  s.f0_good_hz = good.analysis.fit.Find("f0_hz")->value;
  s.q_good = good.analysis.fit.Find("Q")->value;
  s.chi2_good = 1.0 + good.analysis.fit.chi2 / s.dof;

  std::vector<std::pair<std::string, RotorChainParams>> defects = {
      {"one_soft_magnet", NominalWithDefect(o.rotor, DefectClass::kOneSoftMagnet, 1.0)},
      {"two_soft_magnets", NominalWithDefect(o.rotor, DefectClass::kTwoSoftMagnets, 1.0)},
      {"half_soft", NominalWithDefect(o.rotor, DefectClass::kHalfSoft, 1.0)},
      {"all_soft", NominalWithDefect(o.rotor, DefectClass::kAllSoft, 1.0)}};
  for (double f : o.bond_fractions)
    defects.push_back(
        {"weak_bonds:" + Fmt("%.2g", f), NominalWithDefect(o.rotor, DefectClass::kWeakBonds, f)});

  std::vector<Expected> good_clamped;
  for (double c : kClampScales) good_clamped.push_back(ctx.Evaluate(WithFixtureScale(o.rotor, c)));

  for (const auto& [name, params] : defects)
    s.classes.push_back(PredictClass(ctx, o, s, good, good_clamped, name, params));
  const double upper_spread = UpperSpread(o);
  for (const char* which : {"one_magnet", "all_magnets"})
    s.pod.push_back(PredictPod(ctx, o, good, which, upper_spread));

  s.usable = true;
  int separable = 0;
  for (const auto& c : s.classes) separable += c.separable ? 1 : 0;
  s.message = std::to_string(separable) + " of " + std::to_string(s.classes.size()) +
              " defect classes separable by " + Fmt("%.3g", o.required_sigmas) +
              " sigma in this fixture (k_fixture " + Fmt("%.0f", s.k_fixture_nm_per_rad) +
              " N m/rad, good f0 " + Fmt("%.1f", s.f0_good_hz) + " Hz)";
  return s;
}

}  // namespace eol::analysis
