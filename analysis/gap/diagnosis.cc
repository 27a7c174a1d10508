#include "analysis/gap/diagnosis.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include "analysis/gap/calibration.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

// chi2 and dof per distinct frequency, pooled over units, as residual.h's NoiseTerms (sigma
// with its degrees of freedom); r2 and expected: sum |r|^2 and its expectation.
struct Pooled {
  std::vector<double> f, chi2, dof;
  double r2 = 0.0, expected = 0.0;

  double Z() const {
    double c = 0.0, d = 0.0;
    for (std::size_t k = 0; k < f.size(); ++k) {
      c += chi2[k];
      d += dof[k];
    }
    return ChiSquareZ(c, d);
  }
  // The factor sigma would need to make the mean |r|^2 its expectation.
  double SigmaScale() const { return expected > 0.0 ? std::sqrt(r2 / expected) : 1.0; }
};

Pooled Pool(const NominalNetwork& n, std::span<const AppliedEffect> effects,
            const std::vector<GapUnit>& units) {
  std::map<double, std::pair<double, double>> acc;
  Pooled p;
  for (const GapUnit& u : units)
    for (std::size_t k = 0; k < u.size(); ++k) {
      const double r2 = std::norm(LineResidual(u, k, EvaluateNetwork(n, effects, u.freq_hz[k])));
      const NoiseLine line = NoiseTerms(r2, u.sigma_dof);
      auto& a = acc[u.freq_hz[k]];
      a.first += line.chi2;
      a.second += line.dof;
      p.r2 += r2;
      p.expected += ExpectedR2(u.sigma_dof);
    }
  for (const auto& [f, v] : acc) {
    p.f.push_back(f);
    p.chi2.push_back(v.first);
    p.dof.push_back(v.second);
  }
  return p;
}

double BandG(const Pooled& p, const GapBand& b) {
  double c = 0.0, d = 0.0;
  for (int k = b.first; k <= b.last; ++k) {
    c += p.chi2[static_cast<std::size_t>(k)];
    d += p.dof[static_cast<std::size_t>(k)];
  }
  return d > 0.0 ? std::sqrt(c / d) : 0.0;
}

std::vector<BandGap> WithGaps(const std::vector<GapBand>& bands, const Pooled& before,
                              const Pooled& after) {
  std::vector<BandGap> out;
  for (const GapBand& b : bands) out.push_back({b, BandG(before, b), BandG(after, b)});
  return out;
}

std::string JoinNames(const std::vector<AppliedEffect>& effects) {
  std::string s;
  for (const AppliedEffect& e : effects)
    s += (s.empty() ? "" : "+") + std::string(ToString(e.kind));
  return s;
}

// The first torsional mode of the nominal with the structural effects among `effects`
// (fixture_compliance, coupled_inertia, adhesive_creep): where Re of the motional part
// Z - (R + s L) peaks inside the band (analysis/README.md 2: Re Z peaks at f0), on a fine log grid;
// 0 when it has no peak inside (the structure moved every mode out). Impedance only.
double FirstModeHz(const NominalNetwork& n, std::span<const AppliedEffect> effects, double f_lo,
                   double f_hi) {
  std::vector<AppliedEffect> structural;
  for (const AppliedEffect& e : effects)
    if (e.kind == EffectKind::kFixtureCompliance || e.kind == EffectKind::kCoupledInertia ||
        e.kind == EffectKind::kAdhesiveCreep)
      structural.push_back(e);
  const int points = 4000;
  int best_i = 0;
  double best = -std::numeric_limits<double>::infinity();
  auto freq = [&](int i) { return f_lo * std::pow(f_hi / f_lo, i / (points - 1.0)); };
  for (int i = 0; i < points; ++i) {
    const double f = freq(i);
    const Cplx winding(n.motional.r_ohm, 2.0 * std::numbers::pi * f * n.motional.l_h);
    const double re = (EvaluateNetwork(n, structural, f) - winding).real();
    if (re > best) {
      best = re;
      best_i = i;
    }
  }
  return best_i == 0 || best_i == points - 1 ? 0.0 : freq(best_i);
}

// Two modes within 4 % of each other draw one peak at these rotors' Q of about 50 (two
// half-power bandwidths; gap_bench.h draws second modes at least 4 % from f0 for the same
// reason): a second_mode there is the measured mode re-drawn, the nominal's own f0, Q and
// Rp refitted (the calibration of GapSplit), not a mode of another part.
constexpr double kModeSeparation = 0.04;

RankedEffect Rank(const EffectFitter& fitter, const EffectFit& fit, const GapOptions& o) {
  RankedEffect r;
  r.effects = fit.effects;
  r.effect = JoinNames(fit.effects);
  r.chi2 = fit.chi2;
  r.cost = fit.cost;
  r.nominal = fit.nominal;
  r.shift = fit.shift;
  r.prior = fit.prior;
  r.bic = fit.cost + fit.prior + fit.n_params * std::log(std::max(fit.residuals, 1));
  r.score = fit.Evidence() + PriorPenalty(fit.effects, o);
  r.gap_after = fit.residuals > 0 ? std::sqrt(fit.chi2 / fit.residuals) : 0.0;
  r.converged = fit.converged;
  for (std::size_t e = 0; e < fit.effects.size(); ++e) {
    const EffectSpec spec = fitter.Spec(fit.effects[e].kind);
    for (std::size_t p = 0; p < spec.params.size(); ++p) {
      const double sigma = e < fit.sigma.size() && p < fit.sigma[e].size()
                               ? fit.sigma[e][p]
                               : std::numeric_limits<double>::quiet_NaN();
      r.params.push_back(
          {spec.params[p].name, spec.params[p].unit, fit.effects[e].params[p], sigma});
    }
  }
  for (const AppliedEffect& e : fit.effects) {
    for (const DerivedParam& d : DeriveEffectParams(fit.nominal, e)) {
      // First-order sigma of a derived value is not propagated here; the fitted one is.
      r.params.push_back({d.name, d.unit, d.value, std::numeric_limits<double>::quiet_NaN()});
    }
  }
  std::string why;
  for (const AppliedEffect& e : fit.effects) {
    if (!IsPlausible(fitter.Spec(e.kind), e, &why)) {
      r.plausible = false;
      r.rejected = std::string(ToString(e.kind)) + ": implausible, " + why;
      break;
    }
  }
  const NominalNetwork& nominal = fit.nominal;
  for (const AppliedEffect& e : fit.effects) {
    if (!r.plausible || e.kind != EffectKind::kSecondMode ||
        nominal.quantity != Quantity::kImpedanceOhm)
      continue;
    const double lo = fitter.f_lo_hz(), hi = fitter.f_hi_hz();
    const double first = FirstModeHz(nominal, fit.effects, lo, hi);
    const double f0 = fitter.nominal().motional.f0_hz;  // the simulation's mode
    std::ostringstream os;
    os.precision(4);
    if (first > 0.0 && std::abs(e.params[0] / first - 1.0) < kModeSeparation) {
      os << "second_mode: at " << e.params[0] << " Hz, within 4 % of the first mode (" << first
         << " Hz): the measured mode re-drawn, not a second one";
    } else if (first == 0.0 && f0 > lo && f0 < hi) {
      // The structure or the calibration moved the simulation's in-band mode out of the band:
      // the second_mode is then the only mode left there, the measured one re-drawn.
      os << "second_mode: at " << e.params[0] << " Hz, the only mode in the band (the other "
         << "effects move the nominal's " << f0 << " Hz out of it): the measured mode re-drawn";
    }
    if (!os.str().empty()) {
      r.plausible = false;
      r.rejected = os.str();
    }
  }
  if (r.plausible && !fit.converged) {
    r.plausible = false;
    r.rejected = "the fit did not converge";
  }
  return r;
}

bool BetterRank(const RankedEffect& a, const RankedEffect& b) {
  if (a.plausible != b.plausible) return a.plausible;
  return a.score < b.score;
}

LineMask ParityMask(const std::vector<GapUnit>& units, int parity) {
  LineMask m(units.size());
  for (std::size_t u = 0; u < units.size(); ++u) {
    m[u].resize(units[u].size());
    for (std::size_t k = 0; k < units[u].size(); ++k)
      m[u][k] = (k % 2) == static_cast<std::size_t>(parity);
  }
  return m;
}

LineMask UnitMask(const std::vector<GapUnit>& units, std::size_t which, bool invert) {
  LineMask m(units.size());
  for (std::size_t u = 0; u < units.size(); ++u)
    m[u].assign(units[u].size(), static_cast<char>((u == which) != invert));
  return m;
}

// (fit on, predict): one unit -> two-fold interleaved lines; several -> leave-one-unit-out.
using Fold = std::pair<LineMask, LineMask>;
std::vector<Fold> HeldOutFolds(const std::vector<GapUnit>& units, std::string* method) {
  std::vector<Fold> folds;
  if (units.size() == 1) {
    *method = "interleaved-2fold";
    folds.push_back({ParityMask(units, 0), ParityMask(units, 1)});
    folds.push_back({ParityMask(units, 1), ParityMask(units, 0)});
  } else {
    *method = "leave-one-unit-out";
    for (std::size_t u = 0; u < units.size(); ++u)
      folds.push_back({UnitMask(units, u, true), UnitMask(units, u, false)});
  }
  return folds;
}

// Held-out g of `effects` with the nominal as `mode` says, refitted on each fold (HeldOutFolds)
// from `from`, against the simulation's nominal on the same lines.
HeldOutGap HeldOut(const EffectFitter& fitter, const NominalNetwork& from, NominalFit mode,
                   const std::vector<AppliedEffect>& effects, int iterations) {
  const std::vector<GapUnit>& units = fitter.units();
  HeldOutGap h;
  const std::vector<Fold> folds = HeldOutFolds(units, &h.method);
  double before = 0.0, after = 0.0;
  int n = 0;
  for (const auto& [fit_on, predict] : folds) {
    const EffectFit fit = fitter.FitFrom(from, mode, effects, fit_on, iterations);
    int m = 0;
    double cost = 0.0;
    after += fitter.Chi2With(fit.nominal, fit.effects, predict, &cost);
    before += fitter.Chi2({}, predict, &m);
    h.cost_after += cost;
    h.cost_before += fitter.Cost({}, predict);
    n += m;
  }
  h.gap_before = n > 0 ? std::sqrt(before / n) : 0.0;
  h.gap_after = n > 0 ? std::sqrt(after / n) : 0.0;
  return h;
}

// The lowest cost + prior of the fits of `effects` in `mode` from each start nominal.
EffectFit BestFrom(const EffectFitter& fitter, const std::vector<NominalNetwork>& starts,
                   NominalFit mode, const std::vector<AppliedEffect>& effects, const LineMask& mask,
                   int iterations) {
  EffectFit best;
  best.cost = std::numeric_limits<double>::infinity();
  for (const NominalNetwork& n : starts) {
    EffectFit f = fitter.FitFrom(n, mode, effects, mask, iterations);
    if (std::isfinite(f.cost) && f.cost + f.prior < best.cost + best.prior) best = std::move(f);
  }
  return best;
}

// The simulation's nominal and, when the first unit calibrates on its own, that unit's motional
// part (a large f0 shift is out of LM's reach from the simulation's values).
std::vector<NominalNetwork> CalibrationStarts(const EffectFitter& fitter) {
  const NominalNetwork& nominal = fitter.nominal();
  std::vector<NominalNetwork> starts = {nominal};
  const GapUnit& first = fitter.units().front();
  Frf h;
  h.quantity = nominal.quantity;
  h.freq_hz = first.freq_hz;
  h.value = first.value;
  h.sigma = first.sigma;
  const CalibrationSummary fresh = CalibrateNominal(h, CalibrationOptions{});
  if (fresh.usable) {
    NominalNetwork n = nominal;
    n.motional = fresh.nominal.motional;
    n.rigid = fresh.nominal.rigid;
    starts.push_back(n);
  }
  return starts;
}

// The nominal alone, calibrated within the tolerances (the diagnosis' "none"; the simulation's
// nominal itself when the options keep it fixed) and beyond them (no prior).
struct Calibrations {
  EffectFit within, beyond;
};
Calibrations Calibrate(const EffectFitter& fitter, const GapOptions& o) {
  const std::vector<NominalNetwork> starts = CalibrationStarts(fitter);
  Calibrations c;
  c.within = BestFrom(fitter, starts, fitter.mode(), {}, {}, o.max_iterations);
  c.beyond = BestFrom(fitter, starts, NominalFit::kFree, {}, {}, o.max_iterations);
  if (!(c.beyond.cost <= c.within.cost)) c.beyond = c.within;  // no prior can only fit better
  return c;
}

// The three ways the gap shrinks and the old two-way split (GapSplit), with held-out g.
GapSplit SplitGap(const EffectFitter& fitter, const Calibrations& cal, const RankedEffect& answer,
                  const HeldOutGap& answer_heldout, const GapOptions& o) {
  GapSplit s;
  const LineMask all;
  int residuals = 0;
  const double chi2_nominal = fitter.Chi2({}, all, &residuals);
  double expected = 0.0;
  for (const GapUnit& u : fitter.units())
    expected += ExpectedR2(u.sigma_dof) * static_cast<double>(u.size());
  expected /= residuals / 2.0;
  auto g_of = [&](double chi2) { return std::sqrt(chi2 / residuals); };
  EffectFit both = cal.beyond;
  if (!answer.effects.empty()) {
    // From the answer's calibrated nominal (the effect as diagnosed) and from the free one.
    both = BestFrom(fitter, {answer.nominal, cal.beyond.nominal}, NominalFit::kFree, answer.effects,
                    all, o.max_iterations);
    if (!(both.cost <= cal.beyond.cost)) both = cal.beyond;  // the effect may not make it worse
  }
  s.refit = cal.beyond.nominal;
  s.refit_effect = both.nominal;
  s.effect = both.effects;
  s.g_nominal = g_of(chi2_nominal);
  s.g_within = g_of(cal.within.chi2);
  s.g_refit = s.g_beyond = g_of(cal.beyond.chi2);
  s.g_structure = answer.effects.empty() ? s.g_within : g_of(answer.chi2);
  s.g_refit_effect = g_of(both.chi2);
  const double x0 = s.g_nominal * s.g_nominal - expected;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  auto share = [&](double g_from, double g_to) {
    return x0 > 0.0 ? (g_from * g_from - g_to * g_to) / x0 : nan;
  };
  s.share_within = share(s.g_nominal, s.g_within);
  s.share_beyond = share(s.g_within, s.g_beyond);
  s.share_structure_within = share(s.g_within, s.g_structure);
  s.share_left_within = x0 > 0.0 ? (s.g_structure * s.g_structure - expected) / x0 : nan;
  s.share_calibration = share(s.g_nominal, s.g_refit);
  s.share_structure = share(s.g_refit, s.g_refit_effect);
  s.share_left = x0 > 0.0 ? (s.g_refit_effect * s.g_refit_effect - expected) / x0 : nan;
  // Held out: each refitted on the folds from its full fit, which half the lines only nudge.
  const int iterations = std::min(o.max_iterations, 60);
  const HeldOutGap within = HeldOut(fitter, cal.within.nominal, fitter.mode(), {}, iterations);
  const HeldOutGap beyond = HeldOut(fitter, cal.beyond.nominal, NominalFit::kFree, {}, iterations);
  const HeldOutGap together =
      HeldOut(fitter, both.nominal, NominalFit::kFree, both.effects, iterations);
  s.heldout_method = within.method;
  s.heldout_g_nominal = within.gap_before;
  s.heldout_g_within = within.gap_after;
  s.heldout_g_beyond = beyond.gap_after;
  s.heldout_g_structure = answer.effects.empty() ? within.gap_after : answer_heldout.gap_after;
  s.heldout_g_refit_effect = together.gap_after;
  s.available = true;
  return s;
}

// How many tolerances make a parameter "outside its tolerance" in the finding.
constexpr double kOutsideTolerances = 2.0;

// A calibration that needs parameters outside their tolerances (CalibrationFinding).
CalibrationFinding FindBeyondTolerance(const EffectFitter& fitter, const Calibrations& cal,
                                       const GapOptions& o) {
  CalibrationFinding f;
  int residuals = 0;
  fitter.Chi2({}, {}, &residuals);
  f.g_beyond = std::sqrt(cal.beyond.chi2 / residuals);
  f.cost_gain = cal.within.cost + cal.within.prior - cal.beyond.cost;
  const TolerancePrior* prior = fitter.prior();
  if (!prior || cal.beyond.shift.size() != prior->size()) return f;
  f.offsets = prior->Physical(cal.beyond.shift);
  std::sort(f.offsets.begin(), f.offsets.end(), [](const auto& a, const auto& b) {
    return std::abs(a.tolerances) > std::abs(b.tolerances);
  });
  f.found = f.cost_gain >= o.min_score_gain &&
            std::abs(f.offsets.front().tolerances) >= kOutsideTolerances;
  return f;
}

bool CheckUnits(const std::vector<GapUnit>& units, std::string* why) {
  if (units.empty()) {
    *why = "no measured unit";
    return false;
  }
  for (const GapUnit& u : units) {
    const std::string name = u.name.empty() ? "a unit" : "unit " + u.name;
    if (!(u.sigma_dof == 0.0 || u.sigma_dof > 4.0)) {
      *why = name + ": sigma_dof must be 0 (exact sigma) or above 4";
      return false;
    }
    if (u.size() < 5 || u.value.size() != u.size() || u.sigma.size() != u.size()) {
      *why = name + ": needs at least 5 lines, each with a value and a sigma";
      return false;
    }
    for (std::size_t k = 0; k < u.size(); ++k) {
      if (!(u.freq_hz[k] > 0.0 && std::isfinite(u.freq_hz[k])) ||
          (k > 0 && !(u.freq_hz[k] > u.freq_hz[k - 1])) || !std::isfinite(u.value[k].real()) ||
          !std::isfinite(u.value[k].imag()) || !(u.sigma[k] > 0.0 && std::isfinite(u.sigma[k]))) {
        std::ostringstream os;
        os << name << ": line " << k << " (" << u.freq_hz[k]
           << " Hz) has a bad frequency, value or sigma";
        *why = os.str();
        return false;
      }
    }
  }
  return true;
}

// The units with their residual form (GapOptions::residual_form); the form and the admittance
// lines into *s.
std::vector<GapUnit> FormUnits(const NominalNetwork& nominal, const std::vector<GapUnit>& units,
                               const GapOptions& o, GapSummary* s) {
  std::vector<GapUnit> formed = units;
  std::size_t lines = 0, admittance_lines = 0;
  s->admittance_hz.resize(formed.size());
  for (std::size_t u = 0; u < formed.size(); ++u) {
    ChooseResidualForm(formed[u], nominal.quantity == Quantity::kImpedanceOhm, o.residual_form);
    lines += formed[u].size();
    admittance_lines += formed[u].admittance ? formed[u].size() : 0;
    for (std::size_t k = 0; k < formed[u].admittance_line.size(); ++k)
      if (formed[u].admittance_line[k]) {
        s->admittance_hz[u].push_back(formed[u].freq_hz[k]);
        ++admittance_lines;
      }
  }
  s->residual_form = admittance_lines == 0       ? "impedance"
                     : admittance_lines == lines ? "admittance"
                                                 : "mixed";
  return formed;
}

// No significant band, and the residual either passes the noise test or is uniformly at most
// max_sigma_scale above sigma (the sigma is off, not the model).
bool Consistent(const Pooled& p, const GapOptions& o) {
  return FindGapBands(p.f, p.chi2, p.dof, o.bands).empty() &&
         (p.Z() <= o.noise_z_max || p.SigmaScale() <= o.max_sigma_scale);
}

RankedEffect RankNone(const EffectFit& within) {
  RankedEffect none;
  none.effect = "none";
  none.nominal = within.nominal;
  none.shift = within.shift;
  none.prior = within.prior;
  none.chi2 = within.chi2;
  none.cost = within.cost;
  none.bic = within.cost + within.prior;
  none.score = within.Evidence();
  none.gap_after = within.residuals > 0 ? std::sqrt(within.chi2 / within.residuals) : 0.0;
  return none;
}

// A single's lowest-cost basin and the nominal it sat on: where its pairs start.
struct Seed {
  AppliedEffect effect;
  NominalNetwork nominal;
};

// Every effect of the library that applies, fitted alone (best first); each one's lowest-cost
// basin into *seeds (the pairs start there: the two effects together fit there).
std::vector<RankedEffect> FitSingles(const EffectFitter& fitter,
                                     const std::vector<EffectKind>& library, const GapOptions& o,
                                     std::map<EffectKind, Seed>* seeds) {
  std::vector<RankedEffect> singles;
  const bool mobility = fitter.nominal().quantity == Quantity::kMobility;
  for (EffectKind kind : library) {
    if (mobility && kind != EffectKind::kSecondMode && kind != EffectKind::kChannelDelay) continue;
    const EffectFit fit = fitter.FitKinds({kind}, {}, {}, o.max_iterations);
    if (fit.effects.empty()) continue;
    (*seeds)[kind] = fit.lowest_cost.empty()
                         ? Seed{fit.effects.front(), fit.nominal}
                         : Seed{fit.lowest_cost.front(), fit.lowest_cost_nominal};
    singles.push_back(Rank(fitter, fit, o));
  }
  std::sort(singles.begin(), singles.end(), BetterRank);
  return singles;
}

// The pairs to fit: the pair_candidates best singles among themselves, and the best single
// with every other.
std::vector<RankedEffect> FitPairs(const EffectFitter& fitter,
                                   const std::vector<RankedEffect>& singles,
                                   std::map<EffectKind, Seed>& seeds, const RankedEffect& best,
                                   const GapOptions& o) {
  std::set<std::pair<EffectKind, EffectKind>> pairs;
  auto add = [&](EffectKind a, EffectKind b) {
    if (a == b || !seeds.count(a) || !seeds.count(b)) return;
    pairs.insert({std::min(a, b), std::max(a, b)});
  };
  const std::size_t top = std::min<std::size_t>(singles.size(), o.pair_candidates);
  for (std::size_t i = 0; i < top; ++i)
    for (std::size_t j = i + 1; j < top; ++j)
      add(singles[i].effects.front().kind, singles[j].effects.front().kind);
  for (const auto& [kind, fit] : seeds) add(best.effects.front().kind, kind);
  std::vector<RankedEffect> ranks;
  for (const auto& [a, b] : pairs) {
    const EffectFit fit = fitter.FitKinds({a, b}, {seeds[a].effect, seeds[b].effect}, {},
                                          o.max_iterations, {seeds[a].nominal, seeds[b].nominal});
    if (fit.effects.size() == 2) ranks.push_back(Rank(fitter, fit, o));
  }
  std::sort(ranks.begin(), ranks.end(), BetterRank);
  return ranks;
}

std::string Gain(double v) {
  std::ostringstream os;
  os.precision(3);
  os << v;
  return os.str();
}

// The calibration under `shift` needs a parameter at kOutsideTolerances or more: a structure
// may hide in it (a fixture spring taken up by the stiffness), so the pairs are tried.
bool AtTheEdge(const EffectFitter& fitter, const Eigen::VectorXd& shift) {
  const TolerancePrior* prior = fitter.prior();
  if (!prior || shift.size() != prior->size()) return false;
  for (const ToleranceDeviation& d : prior->Physical(shift))
    if (std::abs(d.tolerances) >= kOutsideTolerances) return true;
  return false;
}

// The pair step (diagnosis.h "Which" 4): a pair wins only when each member is significant
// against the calibrated single of the other, in sample (BIC) and on held-out lines. Returns the
// new winner (or `best`); the pairs go into *ranking, the pairs that beat the winner's evidence
// but failed a test into *rejected with why.
RankedEffect ChoosePair(const EffectFitter& fitter, const std::vector<RankedEffect>& singles,
                        std::map<EffectKind, Seed>& seeds, const RankedEffect& best,
                        const RankedEffect& none, const GapOptions& o,
                        std::map<std::string, HeldOutGap>* heldout,
                        std::vector<RankedEffect>* ranking, std::vector<GapRival>* rejected) {
  const std::vector<RankedEffect> pairs = FitPairs(fitter, singles, seeds, best, o);
  ranking->insert(ranking->end(), pairs.begin(), pairs.end());
  auto single = [&](EffectKind kind) -> const RankedEffect& {
    for (const RankedEffect& r : singles)
      if (r.effects.front().kind == kind) return r;
    return none;
  };
  auto held = [&](const RankedEffect& r) -> const HeldOutGap& {
    auto it = heldout->find(r.effect);
    if (it == heldout->end())
      it = heldout
               ->emplace(r.effect,
                         HeldOut(fitter, r.nominal, fitter.mode(), r.effects, o.max_iterations))
               .first;
    return it->second;
  };
  for (const RankedEffect& pair : pairs) {
    if (!pair.plausible || pair.score >= best.score) break;
    std::string why;
    for (int m = 0; m < 2 && why.empty(); ++m) {
      // Member m is significant when the pair beats the single of the other member.
      const RankedEffect& other = single(pair.effects[1 - m].kind);
      const std::string member = ToString(pair.effects[m].kind);
      if (pair.bic > other.bic - o.min_score_gain)
        why = member + " is not significant against " + other.effect + " alone (BIC " +
              Gain(other.bic - pair.bic) + " lower, " + Gain(o.min_score_gain) + " needed)";
      else if (held(pair).cost_after > held(other).cost_after - o.min_score_gain)
        why = member + " is not significant against " + other.effect +
              " alone on held-out lines (-2 ln L " +
              Gain(held(other).cost_after - held(pair).cost_after) + " lower, " +
              Gain(o.min_score_gain) + " needed)";
    }
    if (why.empty()) return pair;
    rejected->push_back({pair.effect, pair.score - best.score, "a pair rejected: " + why});
  }
  return best;
}

// The rivals of the winner (GapOptions::rival_margin): every other plausible candidate that is
// an effect by BIC too, within the margin of the winner's evidence, or better than it but
// rejected as a pair; `rival` is the first of the winner's size (as before issue 38).
void AddRivals(const RankedEffect& winner, const RankedEffect& none,
               const std::vector<GapRival>& rejected, const GapOptions& o, GapSummary* s) {
  s->rivals = rejected;
  for (const RankedEffect& r : s->ranking) {
    if (!r.plausible || r.effect == winner.effect || r.effect == "none" ||
        r.bic > none.bic - o.min_score_gain || r.score - winner.score >= o.rival_margin)
      continue;
    bool listed = false;
    for (const GapRival& x : rejected) listed = listed || x.effect == r.effect;
    if (listed) continue;
    s->rivals.push_back({r.effect, std::max(0.0, r.score - winner.score),
                         "the data hardly tell it from the answer"});
    if (s->rival.empty() && r.effects.size() == winner.effects.size()) {
      s->rival = r.effect;
      s->rival_score_gap = std::max(0.0, r.score - winner.score);
    }
  }
}

void Describe(const GapOptions& o, GapSummary* s) {
  std::ostringstream os;
  os.precision(4);
  if (s->effect == "none") {
    os << "no unmodelled effect: ";
    os << (s->split.available && s->split.g_within < s->gap_before - 1e-9
               ? "the nominal calibrated within the design's tolerances leaves a residual "
                 "consistent with the noise (g "
               : "the residual is consistent with the noise (g = ")
       << s->gap_before;
    if (s->split.available && s->split.g_within < s->gap_before - 1e-9)
      os << " -> " << s->split.g_within;
    os << ", noise test z = " << s->noise_z_before << ", no significant band";
    if (s->noise_z_before > o.noise_z_max && s->sigma_scale <= o.max_sigma_scale)
      os << "; uniformly above sigma: it implies sigma x " << s->sigma_scale;
    os << ")";
  } else if (s->effect == "unexplained") {
    os << "the gap (g = " << s->gap_before << ") is not explained by any candidate effect";
  } else if (s->effect == kBeyondTolerance) {
    os << "a calibration beyond the design's tolerances explains the gap: g " << s->gap_before
       << " -> " << s->beyond.g_beyond << "; no candidate effect explains it";
  } else {
    os << s->effect << " explains the gap: g " << s->gap_before << " -> " << s->gap_after
       << " (held out, " << s->heldout.method << ": " << s->heldout.gap_before << " -> "
       << s->heldout.gap_after << ")";
    if (s->noise_z_after > o.noise_z_max || !s->where_after.empty())
      os << "; a significant residual remains";
    if (!s->rival.empty())
      os << "; the data hardly tell it from " << s->rival << " (evidence within "
         << s->rival_score_gap << ")";
  }
  if (s->beyond.found && s->effect != kBeyondTolerance) {
    const ToleranceDeviation& d = s->beyond.offsets.front();
    os << "; a calibration beyond the tolerances would reach g = " << s->beyond.g_beyond << " with "
       << d.name << " at " << d.tolerances << " tolerances (the alternative to "
       << (s->winner.empty() ? "the answer" : "the structure") << ")";
  }
  s->message = os.str();
}

// Where the gap is before and after the answer, and each unit's g.
void WhereAndUnits(const EffectFitter& fitter, const std::vector<GapUnit>& units,
                   const Pooled& before, const std::vector<GapBand>& bands_before,
                   const GapOptions& o, GapSummary* s) {
  const Pooled after = Pool(s->nominal_after, s->winner, fitter.units());
  s->noise_z_after = after.Z();
  s->where = WithGaps(bands_before, before, after);
  s->where_after = WithGaps(FindGapBands(after.f, after.chi2, after.dof, o.bands), before, after);
  for (std::size_t u = 0; u < units.size(); ++u) {
    const LineMask m = UnitMask(fitter.units(), u, false);
    int n = 0;
    const double chi2_before = fitter.Chi2({}, m, &n);
    const double chi2_after = fitter.Chi2With(s->nominal_after, s->winner, m);
    s->units.push_back(
        {units[u].name, n / 2, std::sqrt(chi2_before / n), std::sqrt(chi2_after / n)});
  }
}

}  // namespace

bool GapOptions::IsValid(std::string* why) const {
  auto fail = [&](const char* m) {
    if (why) *why = m;
    return false;
  };
  if (!bands.IsValid(why)) return false;
  if (!(min_score_gain >= 0.0)) return fail("min_score_gain must not be negative");
  if (!(noise_z_max > 0.0)) return fail("noise_z_max must be positive");
  if (!(max_sigma_scale >= 1.0)) return fail("max_sigma_scale must be at least 1");
  if (!(rival_margin >= 0.0 && std::isfinite(rival_margin)))
    return fail("rival_margin must be finite and not negative");
  for (const auto& [kind, odds] : prior_odds)
    if (!(odds > 0.0 && std::isfinite(odds))) return fail("prior_odds must be positive and finite");
  if (pair_candidates < 2) return fail("pair_candidates must be at least 2");
  if (!tolerances.IsValid(why)) return false;
  if (max_iterations < 1) return fail("max_iterations must be at least 1");
  return true;
}

std::vector<double> NormalisedResidual(const NominalNetwork& nominal,
                                       std::span<const AppliedEffect> effects,
                                       const GapUnit& unit) {
  std::vector<double> r(unit.size());
  for (std::size_t k = 0; k < unit.size(); ++k)
    r[k] = std::abs(LineResidual(unit, k, EvaluateNetwork(nominal, effects, unit.freq_hz[k])));
  return r;
}

double PriorPenalty(std::span<const AppliedEffect> effects, const GapOptions& o) {
  double penalty = 0.0;
  for (const AppliedEffect& e : effects)
    for (const auto& [kind, odds] : o.prior_odds)
      if (kind == e.kind) penalty -= 2.0 * std::log(odds);
  return penalty;
}

GapSummary DiagnoseGap(const NominalNetwork& nominal, const std::vector<GapUnit>& units,
                       const GapOptions& o) {
  GapSummary s;
  std::string why;
  if (!o.IsValid(&why)) {
    s.message = "invalid options: " + why;
    return s;
  }
  if (!nominal.IsValid(&why)) {
    s.message = "invalid nominal: " + why;
    return s;
  }
  if (!CheckUnits(units, &why)) {
    s.message = "invalid measurement: " + why;
    return s;
  }
  const std::vector<GapUnit> formed = FormUnits(nominal, units, o, &s);
  EffectFitter fitter(nominal, formed, o.calibrate ? NominalFit::kTolerance : NominalFit::kFixed,
                      o.tolerances);
  s.chi2_before = fitter.Chi2({}, {}, &s.residuals);
  s.gap_before = std::sqrt(s.chi2_before / s.residuals);
  const Pooled pooled_before = Pool(nominal, {}, formed);
  s.noise_z_before = pooled_before.Z();
  s.sigma_scale = pooled_before.SigmaScale();
  const std::vector<GapBand> bands_before =
      FindGapBands(pooled_before.f, pooled_before.chi2, pooled_before.dof, o.bands);

  // "none" is the nominal calibrated within the tolerances; every candidate starts there.
  const Calibrations cal = Calibrate(fitter, o);
  fitter.SetStartNominal(cal.within.nominal);
  const RankedEffect none = RankNone(cal.within);
  const std::vector<EffectKind> library =
      o.effects.empty() ? EffectsFor(nominal.quantity) : o.effects;
  std::map<EffectKind, Seed> seeds;
  const std::vector<RankedEffect> singles = FitSingles(fitter, library, o, &seeds);
  std::vector<RankedEffect> ranking = singles;
  ranking.push_back(none);
  // Whether: BIC, min_score_gain below none; which: the best evidence among those.
  const RankedEffect* best = nullptr;
  for (const RankedEffect& r : singles)
    if (r.plausible && r.bic <= none.bic - o.min_score_gain) {
      best = &r;
      break;
    }
  RankedEffect winner = best ? *best : none;
  std::map<std::string, HeldOutGap> heldout;
  std::vector<GapRival> rejected;
  if (best && o.try_pairs && library.size() >= 2 &&
      (!Consistent(Pool(best->nominal, best->effects, formed), o) ||
       AtTheEdge(fitter, best->shift)))
    winner = ChoosePair(fitter, singles, seeds, *best, none, o, &heldout, &ranking, &rejected);
  std::stable_sort(ranking.begin(), ranking.end(), BetterRank);
  s.ranking = ranking;

  s.beyond = FindBeyondTolerance(fitter, cal, o);
  if (winner.effect == "none") {
    s.effect = Consistent(Pool(none.nominal, {}, formed), o) ? "none"
               : s.beyond.found && Consistent(Pool(cal.beyond.nominal, {}, formed), o)
                   ? kBeyondTolerance
                   : "unexplained";
  } else {
    s.effect = winner.effect;
    s.winner = winner.effects;
    AddRivals(winner, none, rejected, o, &s);
  }
  const bool beyond = s.effect == kBeyondTolerance;
  s.nominal_after = beyond ? cal.beyond.nominal : winner.nominal;
  s.chi2_after = beyond ? cal.beyond.chi2 : winner.chi2;
  s.gap_after = std::sqrt(s.chi2_after / s.residuals);
  if (const TolerancePrior* prior = fitter.prior(); prior && winner.shift.size() == prior->size())
    s.calibration = prior->Physical(winner.shift);
  WhereAndUnits(fitter, units, pooled_before, bands_before, o, &s);
  if (s.winner.empty() || !o.heldout) {
    s.heldout = {s.gap_before, s.gap_before, s.winner.empty() ? "none" : "skipped"};
  } else {
    const auto it = heldout.find(winner.effect);
    s.heldout = it != heldout.end()
                    ? it->second
                    : HeldOut(fitter, winner.nominal, fitter.mode(), s.winner, o.max_iterations);
  }
  s.split = SplitGap(fitter, cal, winner, s.heldout, o);
  Describe(o, &s);
  s.usable = true;
  return s;
}

}  // namespace eol::analysis
