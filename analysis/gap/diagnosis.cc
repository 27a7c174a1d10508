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
  r.bic = fit.cost + fit.n_params * std::log(std::max(fit.residuals, 1));
  r.score = fit.cost + fit.occam + PriorPenalty(fit.effects, o);
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
    for (const DerivedParam& d : DeriveEffectParams(fitter.nominal(), e)) {
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
  const NominalNetwork& nominal = fitter.nominal();
  for (const AppliedEffect& e : fit.effects) {
    if (!r.plausible || e.kind != EffectKind::kSecondMode ||
        nominal.quantity != Quantity::kImpedanceOhm)
      continue;
    const double lo = fitter.f_lo_hz(), hi = fitter.f_hi_hz();
    const double first = FirstModeHz(nominal, fit.effects, lo, hi);
    const double f0 = nominal.motional.f0_hz;
    std::ostringstream os;
    os.precision(4);
    if (first > 0.0 && std::abs(e.params[0] / first - 1.0) < kModeSeparation) {
      os << "second_mode: at " << e.params[0] << " Hz, within 4 % of the first mode (" << first
         << " Hz): the measured mode re-drawn, not a second one";
    } else if (first == 0.0 && f0 > lo && f0 < hi) {
      // The structure moved the nominal's in-band mode out of the band: the second_mode is
      // then the only mode left there, the measured one re-drawn.
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

HeldOutGap HeldOut(const EffectFitter& fitter, const std::vector<AppliedEffect>& winner,
                   const GapOptions& o) {
  const std::vector<GapUnit>& units = fitter.units();
  HeldOutGap h;
  const std::vector<Fold> folds = HeldOutFolds(units, &h.method);
  double before = 0.0, after = 0.0;
  int n = 0;
  for (const auto& [fit_on, predict] : folds) {
    const EffectFit fit = fitter.Fit(winner, fit_on, o.max_iterations);
    int m = 0;
    after += fitter.Chi2(fit.effects, predict, &m);
    before += fitter.Chi2({}, predict);
    h.cost_after += fitter.Cost(fit.effects, predict);
    h.cost_before += fitter.Cost({}, predict);
    n += m;
  }
  h.gap_before = n > 0 ? std::sqrt(before / n) : 0.0;
  h.gap_after = n > 0 ? std::sqrt(after / n) : 0.0;
  return h;
}

// The nominal alone and with the winner, each refitted on the masked lines from the nominal
// and from a fresh calibration of the first unit (a large f0 shift is out of LM's reach from
// the simulation's values); the lower cost wins.
struct Refit {
  NominalNetwork nominal;
  EffectFit fit;
};
Refit BestRefit(const EffectFitter& fitter, const std::vector<NominalNetwork>& starts,
                const std::vector<AppliedEffect>& effects, const LineMask& mask, int iterations) {
  Refit best;
  best.fit.cost = std::numeric_limits<double>::infinity();
  for (const NominalNetwork& n : starts) {
    Refit r;
    r.fit = fitter.FitWithNominal(n, effects, mask, iterations, &r.nominal);
    if (std::isfinite(r.fit.cost) && r.fit.cost < best.fit.cost) best = r;
  }
  return best;
}

GapSplit SplitGap(const EffectFitter& fitter, const std::vector<AppliedEffect>& winner,
                  const GapOptions& o) {
  GapSplit s;
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
  const LineMask all;
  int residuals = 0;
  const double chi2_nominal = fitter.Chi2({}, all, &residuals);
  const double lines = residuals / 2.0;
  double expected = 0.0;
  for (const GapUnit& u : fitter.units())
    expected += ExpectedR2(u.sigma_dof) * static_cast<double>(u.size());
  expected /= lines;
  const Refit cal = BestRefit(fitter, starts, {}, all, o.max_iterations);
  s.refit = cal.nominal;
  Refit both = cal;
  if (!winner.empty()) {
    // From the simulation's nominal (the effect as diagnosed) and from the refitted one.
    both = BestRefit(fitter, {nominal, cal.nominal}, winner, all, o.max_iterations);
    if (!(both.fit.cost <= cal.fit.cost)) both = cal;  // the effect may not make it worse
  }
  s.refit_effect = both.nominal;
  s.effect = both.fit.effects;
  s.g_nominal = std::sqrt(chi2_nominal / residuals);
  s.g_refit = std::sqrt(cal.fit.chi2 / residuals);
  s.g_refit_effect = std::sqrt(both.fit.chi2 / residuals);
  const double x0 = s.g_nominal * s.g_nominal - expected;
  auto excess = [&](double g) { return g * g - expected; };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  s.share_calibration = x0 > 0.0 ? (x0 - excess(s.g_refit)) / x0 : nan;
  s.share_structure = x0 > 0.0 ? (excess(s.g_refit) - excess(s.g_refit_effect)) / x0 : nan;
  s.share_left = x0 > 0.0 ? excess(s.g_refit_effect) / x0 : nan;
  // Held out: interleaved lines (one unit) or leave-one-unit-out, both refitted together from
  // the full fit.
  const std::vector<GapUnit>& units = fitter.units();
  const std::vector<Fold> folds = HeldOutFolds(units, &s.heldout_method);
  double before = 0.0, after = 0.0;
  int n = 0;
  for (const auto& [fit_on, predict] : folds) {
    NominalNetwork refitted;
    // Started at the full fit, which the half of the lines only nudges.
    const EffectFit f = fitter.FitWithNominal(both.nominal, both.fit.effects, fit_on,
                                              std::min(o.max_iterations, 60), &refitted);
    int m = 0;
    after += fitter.Chi2With(refitted, f.effects, predict);
    before += fitter.Chi2({}, predict, &m);
    n += m;
  }
  s.heldout_g_nominal = n > 0 ? std::sqrt(before / n) : 0.0;
  s.heldout_g_refit_effect = n > 0 ? std::sqrt(after / n) : 0.0;
  s.available = true;
  return s;
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
  std::vector<GapUnit> formed = units;
  std::size_t lines = 0, admittance_lines = 0;
  s.admittance_hz.resize(formed.size());
  for (std::size_t u = 0; u < formed.size(); ++u) {
    ChooseResidualForm(formed[u], nominal.quantity == Quantity::kImpedanceOhm, o.residual_form);
    lines += formed[u].size();
    admittance_lines += formed[u].admittance ? formed[u].size() : 0;
    for (std::size_t k = 0; k < formed[u].admittance_line.size(); ++k)
      if (formed[u].admittance_line[k]) {
        s.admittance_hz[u].push_back(formed[u].freq_hz[k]);
        ++admittance_lines;
      }
  }
  s.residual_form = admittance_lines == 0       ? "impedance"
                    : admittance_lines == lines ? "admittance"
                                                : "mixed";
  const EffectFitter fitter(nominal, formed);
  const LineMask all;
  s.chi2_before = fitter.Chi2({}, all, &s.residuals);
  s.gap_before = std::sqrt(s.chi2_before / s.residuals);
  const Pooled pooled_before = Pool(nominal, {}, formed);
  s.noise_z_before = pooled_before.Z();
  s.sigma_scale = pooled_before.SigmaScale();
  const std::vector<GapBand> bands_before =
      FindGapBands(pooled_before.f, pooled_before.chi2, pooled_before.dof, o.bands);
  // No significant band, and the residual either passes the test or is uniformly at most
  // max_sigma_scale above sigma (the sigma is off, not the model).
  const bool nominal_consistent = bands_before.empty() && (s.noise_z_before <= o.noise_z_max ||
                                                           s.sigma_scale <= o.max_sigma_scale);

  // Singles.
  const std::vector<EffectKind> library =
      o.effects.empty() ? EffectsFor(nominal.quantity) : o.effects;
  std::vector<RankedEffect> singles;
  std::map<EffectKind, AppliedEffect> single_fit;
  for (EffectKind kind : library) {
    if (nominal.quantity == Quantity::kMobility && kind != EffectKind::kSecondMode &&
        kind != EffectKind::kChannelDelay)
      continue;
    const EffectFit fit = fitter.FitKinds({kind}, {}, all, o.max_iterations);
    if (fit.effects.empty()) continue;
    // Pairs start from the lowest-cost basin: the two effects together fit there.
    single_fit[kind] = fit.lowest_cost.empty() ? fit.effects.front() : fit.lowest_cost.front();
    singles.push_back(Rank(fitter, fit, o));
  }
  std::sort(singles.begin(), singles.end(), BetterRank);
  RankedEffect none;
  none.effect = "none";
  none.chi2 = s.chi2_before;
  none.cost = fitter.Cost({}, all);
  none.score = none.bic = none.cost;
  none.gap_after = s.gap_before;
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

  // Pairs, when the best single leaves a residual inconsistent with the noise.
  if (best && o.try_pairs && library.size() >= 2) {
    const Pooled after = Pool(nominal, best->effects, formed);
    const bool consistent = FindGapBands(after.f, after.chi2, after.dof, o.bands).empty() &&
                            (after.Z() <= o.noise_z_max || after.SigmaScale() <= o.max_sigma_scale);
    if (!consistent) {
      std::set<std::pair<EffectKind, EffectKind>> pairs;
      auto add = [&](EffectKind a, EffectKind b) {
        if (a == b || !single_fit.count(a) || !single_fit.count(b)) return;
        pairs.insert({std::min(a, b), std::max(a, b)});
      };
      const std::size_t top = std::min<std::size_t>(singles.size(), o.pair_candidates);
      for (std::size_t i = 0; i < top; ++i)
        for (std::size_t j = i + 1; j < top; ++j)
          add(singles[i].effects.front().kind, singles[j].effects.front().kind);
      for (const auto& [kind, fit] : single_fit) add(best->effects.front().kind, kind);
      std::vector<RankedEffect> pair_ranks;
      for (const auto& [a, b] : pairs) {
        const EffectFit fit =
            fitter.FitKinds({a, b}, {single_fit[a], single_fit[b]}, all, o.max_iterations);
        if (fit.effects.size() == 2) pair_ranks.push_back(Rank(fitter, fit, o));
      }
      std::sort(pair_ranks.begin(), pair_ranks.end(), BetterRank);
      // Each member significant on its own: against each member's single fit in sample, and
      // against the winner on held-out lines.
      auto single_bic = [&](EffectKind kind) {
        for (const RankedEffect& r : singles)
          if (r.effects.front().kind == kind) return r.bic;
        return none.bic;
      };
      const HeldOutGap winner_heldout = HeldOut(fitter, best->effects, o);
      for (const RankedEffect& pair : pair_ranks) {
        if (!pair.plausible || pair.score >= winner.score) break;
        if (pair.bic > single_bic(pair.effects[0].kind) - o.min_score_gain ||
            pair.bic > single_bic(pair.effects[1].kind) - o.min_score_gain)
          continue;
        const HeldOutGap h = HeldOut(fitter, pair.effects, o);
        if (h.cost_after <= winner_heldout.cost_after - o.min_score_gain) {
          winner = pair;
          break;
        }
      }
      ranking.insert(ranking.end(), pair_ranks.begin(), pair_ranks.end());
    }
  }
  std::stable_sort(ranking.begin(), ranking.end(), BetterRank);
  s.ranking = ranking;

  if (winner.effect == "none") {
    s.effect = nominal_consistent ? "none" : "unexplained";
  } else {
    s.effect = winner.effect;
    s.winner = winner.effects;
    // The rival: the best other plausible candidate of the winner's size that is an effect too
    // (its BIC passes), within rival_margin of the winner's evidence.
    for (const RankedEffect& r : s.ranking) {
      if (!r.plausible || r.effect == winner.effect || r.effects.size() != winner.effects.size() ||
          r.bic > none.bic - o.min_score_gain)
        continue;
      if (r.score - winner.score < o.rival_margin) {
        s.rival = r.effect;
        s.rival_score_gap = std::max(0.0, r.score - winner.score);
      }
      break;
    }
  }
  s.chi2_after = winner.effect == "none" ? s.chi2_before : winner.chi2;
  s.gap_after = std::sqrt(s.chi2_after / s.residuals);
  const Pooled pooled_after = Pool(nominal, s.winner, formed);
  s.noise_z_after = pooled_after.Z();
  s.where = WithGaps(bands_before, pooled_before, pooled_after);
  s.where_after =
      WithGaps(FindGapBands(pooled_after.f, pooled_after.chi2, pooled_after.dof, o.bands),
               pooled_before, pooled_after);
  for (std::size_t u = 0; u < units.size(); ++u) {
    const LineMask m = UnitMask(formed, u, false);
    int n = 0;
    const double before = fitter.Chi2({}, m, &n);
    const double after = fitter.Chi2(s.winner, m);
    s.units.push_back({units[u].name, n / 2, std::sqrt(before / n), std::sqrt(after / n)});
  }
  if (s.winner.empty() || !o.heldout) {
    s.heldout = {s.gap_before, s.gap_before, s.winner.empty() ? "none" : "skipped"};
  } else {
    s.heldout = HeldOut(fitter, s.winner, o);
  }

  s.split = SplitGap(fitter, s.winner, o);

  std::ostringstream os;
  os.precision(4);
  if (s.effect == "none") {
    os << "no unmodelled effect: the residual is consistent with the noise (g = " << s.gap_before
       << ", noise test z = " << s.noise_z_before << ", no significant band";
    if (s.noise_z_before > o.noise_z_max)
      os << "; uniformly above sigma: it implies sigma x " << s.sigma_scale;
    os << ")";
  } else if (s.effect == "unexplained") {
    os << "the gap (g = " << s.gap_before << ") is not explained by any candidate effect";
  } else {
    os << s.effect << " explains the gap: g " << s.gap_before << " -> " << s.gap_after
       << " (held out, " << s.heldout.method << ": " << s.heldout.gap_before << " -> "
       << s.heldout.gap_after << ")";
    if (s.noise_z_after > o.noise_z_max || !s.where_after.empty())
      os << "; a significant residual remains";
    if (!s.rival.empty())
      os << "; the data hardly tell it from " << s.rival << " (evidence within "
         << s.rival_score_gap << ")";
  }
  s.message = os.str();
  s.usable = true;
  return s;
}

}  // namespace eol::analysis
