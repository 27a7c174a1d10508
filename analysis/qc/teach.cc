#include "analysis/qc/teach.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <stdexcept>

#include "analysis/enum_names.h"
#include "analysis/qc/bond_index.h"
#include "analysis/qc/f0_pressure.h"
#include "analysis/qc/measurement_names.h"
#include "analysis/qc/statistics.h"
#include "analysis/qc/tolerance.h"

namespace eol::analysis {
namespace {

constexpr double kMadToSigma = 1.4826;
constexpr double kMadEfficiency = 0.37;

// Design weights of the false-reject budget (teach.h's table).
constexpr double kPlausibilityWeight = 0.002;
constexpr double kOtherWeight = 0.02;
constexpr double kMaskMaxWeight = 0.20;   // all segments together
constexpr double kMaskMinWeight = 0.005;  // all segments together
constexpr double kResidueWeight = 0.10;
constexpr double kBondIndexWeight = 0.30;
constexpr double kResonanceLoWeight = 0.20;
constexpr double kSecondModeWeight = 0.30;

struct SideWeights {
  double lo = 0.0, hi = 0.0;
  bool defect_lo = false, defect_hi = false;
};

// With the pressure-normalised resonance declared (f0_pressure.h) it takes the f0 lower bound's
// share, and f0 itself keeps plausibility bounds.
SideWeights DesignWeights(const std::string& name, bool f0_normalised) {
  namespace n = names;
  const double p = kPlausibilityWeight;
  if (name == n::kResonanceFHz && f0_normalised) return {p, p, false, false};
  if (name == n::kResonanceFHz || name == n::kResonanceFRefPressureHz)
    return {kResonanceLoWeight, p, true, false};
  if (name == n::kFitChi2PerDof) return {p, 0.35, false, true};
  if (name == n::kResonanceQ) return {0.05, p, true, false};
  if (name == n::kMotionalResidueOhmPerS) return {p, kResidueWeight, false, true};
  if (name == n::kBondIndexPct) return {p, kBondIndexWeight, false, true};
  if (name == n::kSecondModeChi2Drop) return {p, kSecondModeWeight, false, true};
  return {kOtherWeight, kOtherWeight, true, true};
}

// One-sided distribution-free count: the minimum of n units bounds `coverage` from below with
// confidence 1 - coverage^n.
int OneSidedWilksUnitsNeeded(double coverage, double confidence) {
  return static_cast<int>(std::ceil(std::log(1.0 - confidence) / std::log(coverage)));
}

double RobustScale(const std::vector<double>& v, double median) {
  std::vector<double> dev;
  for (double x : v) dev.push_back(std::abs(x - median));
  return kMadToSigma * Median(dev);
}

// Six significant digits: limits written into a recipe stay readable.
double Round6(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  const double scale = std::pow(10.0, 5 - std::floor(std::log10(std::abs(v))));
  return std::round(v * scale) / scale;
}

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

struct CentreScale {
  double centre = 0.0;
  double scale = 0.0;
};

CentreScale CentreAndScale(const std::vector<double>& v, bool robust) {
  CentreScale cs;
  if (robust) {
    cs.centre = Median(v);
    cs.scale = RobustScale(v, cs.centre);
    return cs;
  }
  double sum = 0.0;
  for (double x : v) sum += x;
  cs.centre = sum / static_cast<double>(v.size());
  double ss = 0.0;
  for (double x : v) ss += (x - cs.centre) * (x - cs.centre);
  cs.scale = std::sqrt(ss / static_cast<double>(v.size() - 1));
  return cs;
}

TeachSummary Fail(TeachSummary s, const std::string& why) {
  s.usable = false;
  s.message = why;
  return s;
}

// The golden curves' common grid, or an empty vector with the reason in *why.
bool CommonGrid(const std::vector<const GoldenUnit*>& units, std::string* why) {
  const Frf& first = units.front()->curve;
  for (const GoldenUnit* u : units) {
    const Frf& c = u->curve;
    std::string bad;
    if (c.size() == 0) {
      *why = "golden unit " + u->label + " has no curve";
      return false;
    }
    if (!c.Validate(&bad)) {
      *why = "golden unit " + u->label + ": curve: " + bad;
      return false;
    }
    bool same = c.size() == first.size();
    for (std::size_t k = 0; same && k < c.size(); ++k)
      same = std::abs(c.freq_hz[k] - first.freq_hz[k]) <= 1e-9 * first.freq_hz[k];
    if (!same) {
      *why = "golden unit " + u->label + ": curve is not on the frequency grid of " +
             units.front()->label + " (" + std::to_string(first.size()) + " lines " +
             Num(first.freq_hz.front()) + "-" + Num(first.freq_hz.back()) + " Hz)";
      return false;
    }
  }
  return true;
}

// teach.h: plug-in tails beyond each bound, and their parametric-bootstrap interval.
void ExpectedFalseReject(TeachSummary& s, std::size_t n_units, double confidence) {
  std::map<std::string, const TaughtStatistic*> by_name;
  for (const TaughtStatistic& t : s.statistics) by_name[t.name] = &t;
  auto reject_share = [&](auto centre_of, auto scale_of) {
    double pass = 1.0;
    for (const TaughtBound& b : s.taught_bounds) {
      const TaughtStatistic& t = *by_name.at(b.statistic);
      const double z = (b.lo ? centre_of(t) - b.limit : b.limit - centre_of(t)) / scale_of(t);
      pass *= 1.0 - NormalCdf(-z);
    }
    return 1.0 - pass;
  };
  s.expected_false_reject = reject_share([](const TaughtStatistic& t) { return t.centre; },
                                         [](const TaughtStatistic& t) { return t.scale; });
  const double n = static_cast<double>(n_units);
  std::mt19937_64 rng(20261124);
  std::normal_distribution<double> normal(0.0, 1.0);
  std::chi_squared_distribution<double> chi2(n - 1.0);
  const int draws = 4000;
  std::vector<double> shares;
  std::map<std::string, std::pair<double, double>> drawn;  // name -> (centre, scale)
  for (int i = 0; i < draws; ++i) {
    for (const TaughtStatistic& t : s.statistics) {
      const double sd = t.scale * std::sqrt((n - 1.0) / chi2(rng));
      drawn[t.name] = {t.centre + sd * normal(rng) / std::sqrt(n), sd};
    }
    shares.push_back(reject_share([&](const TaughtStatistic& t) { return drawn[t.name].first; },
                                  [&](const TaughtStatistic& t) { return drawn[t.name].second; }));
  }
  // The expected share of new good units rejected, given the golden ones: the mean over the
  // draws (the plug-in value sits low in the tail when the scale is uncertain).
  double sum = 0.0;
  for (double v : shares) sum += v;
  s.expected_false_reject = sum / static_cast<double>(shares.size());
  std::sort(shares.begin(), shares.end());
  auto at = [&](double q) {
    return shares[std::min(shares.size() - 1, static_cast<std::size_t>(q * shares.size()))];
  };
  s.false_reject_lo = at(0.5 * (1.0 - confidence));
  s.false_reject_hi = at(0.5 * (1.0 + confidence));
}

}  // namespace

const char* ToString(TeachMethod m) {
  switch (m) {
    case TeachMethod::kToleranceInterval:
      return "tolerance_interval";
    case TeachMethod::kMad:
      return "mad";
  }
  return "tolerance_interval";
}

TeachMethod ParseTeachMethod(std::string_view name) {
  return ParseEnumOrThrow("method", name, kAllTeachMethods);
}

void to_json(nlohmann::json& j, const TeachMethod& m) { j = ToString(m); }

void from_json(const nlohmann::json& j, TeachMethod& m) {
  if (!j.is_string())
    throw std::invalid_argument(
        "method: must be a string (accepted: " + AcceptedNames(kAllTeachMethods) + ")");
  m = ParseTeachMethod(j.get<std::string>());
}

bool TeachOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (allocation != "physics" && allocation != "even")
    return fail("allocation must be physics or even (got " + allocation + ")");
  if (!(confidence > 0.5 && confidence < 1.0)) return fail("confidence must be in (0.5, 1)");
  if (!(coverage > 0.5 && coverage < 1.0)) return fail("coverage must be in (0.5, 1)");
  if (!(outlier_z >= 2.0)) return fail("outlier_z must be at least 2");
  if (!(width_margin > 0.0)) return fail("width_margin must be positive");
  if (mask_segments < 0 || mask_segments > 200) return fail("mask_segments must be in [0, 200]");
  if (!(mask_guard_sigma >= 0.0)) return fail("mask_guard_sigma must not be negative");
  if (!(marginal_scales >= 0.0)) return fail("marginal_scales must not be negative");
  if (!(known_bad_max_donation >= 0.0 && known_bad_max_donation <= 1.0))
    return fail("known_bad_max_donation must be in [0, 1]");
  if (!(bond_residue_to_f0 > 0.0 && bond_residue_to_f0 <= kMaxResidueToF0))
    return fail("bond_residue_to_f0 must be in (0, 1000]");
  return true;
}

namespace {

// A run of mask lines: outside the band where the good units' resonance may lie.
struct Run {
  std::string name;
  std::size_t a = 0, b = 0;  // [a, b) of the grid's lines
  std::size_t segments = 0;
};

// A statistic with its centre, scale and the bounds it gets (declared sides only).
struct Stat {
  TaughtStatistic t;
  bool want_lo = false, want_hi = false;
  double w_lo = 0.0, w_hi = 0.0;  // design weights ("physics")
  bool defect_lo = false, defect_hi = false;
  double k_lo = 0.0, k_hi = 0.0;
};

// The false-reject budget alpha, shared by the bounds in proportion to their weights.
struct Budget {
  double alpha = 0.0;
  double weight_sum = 0.0;
  bool even = false;
  double n_eff = 0.0;
  double confidence = 0.0;
  std::map<double, double> factors;  // share -> one-sided factor

  double Share(double weight) const { return alpha * weight / weight_sum; }
  double Factor(double share) {
    const auto it = factors.find(share);
    if (it != factors.end()) return it->second;
    return factors[share] = ToleranceFactorOneSided(n_eff, 1.0 - share, confidence);
  }
  // Where a bound of this weight lies (the statistic's lower or upper side).
  double Lo(const Stat& st, double weight) {
    return st.t.centre - Factor(Share(weight)) * st.t.scale;
  }
  double Hi(const Stat& st, double weight) {
    return st.t.centre + Factor(Share(weight)) * st.t.scale;
  }
};

// Every golden (and known-bad) unit must carry every declared measurement, finite; the reason
// when not ("" when the inputs may be taught).
std::string CheckInputs(const std::vector<MeasurementSpec>& declared,
                        const std::vector<GoldenUnit>& golden, const TeachOptions& o,
                        const std::vector<GoldenUnit>& known_bad) {
  std::string why;
  if (!o.IsValid(&why)) return "teach options: " + why;
  if (declared.empty()) return "the recipe declares no scalar limit to teach";
  for (const auto* set : {&golden, &known_bad})
    for (const GoldenUnit& u : *set)
      for (const MeasurementSpec& d : declared) {
        const auto it = u.values.find(d.name);
        if (it == u.values.end() || !std::isfinite(it->second))
          return std::string(set == &golden ? "golden" : "known-bad") + " unit " + u.label +
                 " has no finite value of " + d.name;
      }
  if (!known_bad.empty() && o.allocation != "physics")
    return "known-bad units need allocation physics (the even split has no share to move)";
  return "";
}

// Outliers: robust z over all given units, any measurement. The units kept; the others named
// in *rejected.
std::vector<const GoldenUnit*> DropOutliers(const std::vector<MeasurementSpec>& declared,
                                            const std::vector<GoldenUnit>& golden, double outlier_z,
                                            std::vector<std::string>* rejected) {
  std::set<std::size_t> out;
  for (const MeasurementSpec& d : declared) {
    std::vector<double> v;
    for (const GoldenUnit& u : golden) v.push_back(u.values.at(d.name));
    if (v.size() < 3) break;
    const double med = Median(v);
    const double sc = RobustScale(v, med);
    if (!(sc > 0.0)) continue;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const double z = std::abs(v[i] - med) / sc;
      if (z > outlier_z && out.insert(i).second)
        rejected->push_back(golden[i].label + ": " + d.name + " = " + Num(v[i]) +
                            ", robust z = " + Num(z));
    }
  }
  std::vector<const GoldenUnit*> used;
  for (std::size_t i = 0; i < golden.size(); ++i)
    if (!out.count(i)) used.push_back(&golden[i]);
  return used;
}

// The band [*lo, *hi] where the good units' resonance may lie (teach.h "Curve masks"); false
// when a unit carries no resonance_f_hz and positive resonance_q.
bool ResonanceBand(const std::vector<const GoldenUnit*>& used, double* lo, double* hi) {
  double ex_lo = INFINITY, ex_hi = -INFINITY;
  std::vector<double> bandwidths;
  for (const GoldenUnit* u : used) {
    const auto f0 = u->values.find("resonance_f_hz"), q = u->values.find("resonance_q");
    if (f0 == u->values.end() || q == u->values.end() || !(q->second > 0.0)) return false;
    ex_lo = std::min(ex_lo, f0->second);
    ex_hi = std::max(ex_hi, f0->second);
    bandwidths.push_back(f0->second / q->second);
  }
  const double w = 5.0 * Median(bandwidths) + 0.5 * (ex_hi - ex_lo);
  *lo = ex_lo - w;
  *hi = ex_hi + w;
  return true;
}

// The runs of mask lines, each with its share of the segments; empty when no mask is taught
// (*note says why, or where the masks leave the resonance out).
std::vector<Run> MaskRuns(const std::vector<const GoldenUnit*>& used, const TeachOptions& o,
                          std::string* note) {
  std::vector<Run> runs;
  if (o.mask_segments <= 0) return runs;
  std::string why;
  if (!CommonGrid(used, &why)) {
    *note = "; no mask taught: " + why;
    return runs;
  }
  const Frf& grid = used.front()->curve;
  if (grid.size() < 2 * static_cast<std::size_t>(o.mask_segments)) {
    *note = "; no mask taught: fewer than 2 lines per segment";
    return runs;
  }
  double ex_lo = 0.0, ex_hi = 0.0;
  if (ResonanceBand(used, &ex_lo, &ex_hi)) {
    std::size_t k = 0;
    while (k < grid.size() && grid.freq_hz[k] < ex_lo) ++k;
    runs.push_back(Run{"re_z_taught_below", 0, k, 0});
    std::size_t j = k;
    while (j < grid.size() && grid.freq_hz[j] <= ex_hi) ++j;
    runs.push_back(Run{"re_z_taught_above", j, grid.size(), 0});
    *note = "; masks exclude " + Num(ex_lo) + "-" + Num(ex_hi) +
            " Hz, where the good units' resonance lies (judged by its scalar limits)";
  } else {
    runs.push_back(Run{"re_z_taught", 0, grid.size(), 0});
  }
  std::erase_if(runs, [](const Run& r) { return r.b < r.a + 4; });
  std::size_t total = 0;
  for (const Run& r : runs) total += r.b - r.a;
  for (Run& r : runs)
    r.segments = std::clamp<std::size_t>(
        static_cast<std::size_t>(
            std::lround(static_cast<double>(o.mask_segments) * static_cast<double>(r.b - r.a) /
                        static_cast<double>(total))),
        1, (r.b - r.a) / 2);
  if (runs.empty()) *note = "; no mask taught: the resonance band covers the whole curve";
  return runs;
}

// The declared measurements' statistics; "" or the reason none can be learned.
std::string ScalarStats(const std::vector<MeasurementSpec>& declared,
                        const std::vector<const GoldenUnit*>& used, bool robust, bool f0_normalised,
                        std::vector<Stat>* stats) {
  for (const MeasurementSpec& d : declared) {
    std::vector<double> v;
    for (const GoldenUnit* u : used) v.push_back(u->values.at(d.name));
    const CentreScale cs = CentreAndScale(v, robust);
    if (!(cs.scale > 0.0))
      return "no spread in " + d.name + " among the golden units (" + std::to_string(used.size()) +
             " units, all equal?): a limit cannot be learned from it";
    const SideWeights sw = DesignWeights(d.name, f0_normalised);
    stats->push_back(Stat{TaughtStatistic{d.name, cs.centre, cs.scale, 0.0, 0.0},
                          d.limit.lo.has_value(), d.limit.hi.has_value(), sw.lo, sw.hi,
                          sw.defect_lo, sw.defect_hi});
  }
  return "";
}

// Per mask segment: the units' max Re Z (an upper bound) and min Re Z (a lower one).
void AddMaskStats(const std::vector<Run>& runs, const std::vector<const GoldenUnit*>& used,
                  bool robust, std::vector<Stat>* stats) {
  std::size_t segments_total = 0;
  for (const Run& r : runs) segments_total += r.segments;
  const Frf& grid = used.front()->curve;
  for (const Run& run : runs) {
    const std::size_t lines = run.b - run.a, segs = run.segments;
    for (std::size_t g = 0; g < segs; ++g) {
      const std::size_t a = run.a + g * lines / segs, b = run.a + (g + 1) * lines / segs;
      std::vector<double> maxima, minima;
      for (const GoldenUnit* u : used) {
        double mx = -INFINITY, mn = INFINITY;
        for (std::size_t k = a; k < b; ++k) {
          mx = std::max(mx, u->curve.value[k].real());
          mn = std::min(mn, u->curve.value[k].real());
        }
        maxima.push_back(mx);
        minima.push_back(mn);
      }
      const CentreScale hi = CentreAndScale(maxima, robust), lo = CentreAndScale(minima, robust);
      const std::string band = "[" + Num(grid.freq_hz[a]) + "-" + Num(grid.freq_hz[b - 1]) + " Hz]";
      const double per = 1.0 / static_cast<double>(segments_total);
      stats->push_back(Stat{TaughtStatistic{run.name + band + " max", hi.centre, hi.scale, 0, 0},
                            false, true, 0.0, kMaskMaxWeight * per, false, true});
      stats->push_back(Stat{TaughtStatistic{run.name + band + " min", lo.centre, lo.scale, 0, 0},
                            true, false, kMaskMinWeight * per, 0.0, false, false});
    }
  }
}

// The budget's shares and factors, and the units needed (teach.h); "" or why the golden units
// are too few.
std::string SetBudget(TeachSummary& s, const std::vector<Stat>& stats, const TeachOptions& o,
                      bool robust, Budget* budget) {
  budget->alpha = 1.0 - o.coverage;
  budget->confidence = o.confidence;
  budget->even = o.allocation == "even";
  s.bounds = 0;
  double largest = 0.0;
  for (const Stat& st : stats) {
    s.bounds += (st.want_lo ? 1 : 0) + (st.want_hi ? 1 : 0);
    budget->weight_sum += (st.want_lo ? st.w_lo : 0.0) + (st.want_hi ? st.w_hi : 0.0);
    largest = std::max({largest, st.want_lo ? st.w_lo : 0.0, st.want_hi ? st.w_hi : 0.0});
  }
  const double alpha = budget->alpha;
  int needed = 0;
  if (budget->even) {
    s.p_bound = 1.0 - 2.0 * alpha / s.bounds;
    s.k_factor = ToleranceFactorTwoSided(budget->n_eff, s.p_bound, o.confidence);
    needed = ToleranceUnitsNeeded(s.p_bound, o.confidence, o.width_margin);
    s.units_needed_distribution_free = WilksUnitsNeeded(s.p_bound, o.confidence);
  } else {
    s.p_bound = 1.0 - alpha * largest / budget->weight_sum;
    s.k_factor = ToleranceFactorOneSided(budget->n_eff, s.p_bound, o.confidence);
    needed = OneSidedUnitsNeeded(s.p_bound, o.confidence, o.width_margin);
    s.units_needed_distribution_free = OneSidedWilksUnitsNeeded(s.p_bound, o.confidence);
  }
  s.units_needed = robust ? static_cast<int>(std::ceil(needed / kMadEfficiency)) : needed;
  if (s.units_used >= s.units_needed) return "";
  if (!o.allow_few_units)
    return "too few golden units: " + std::to_string(s.units_used) + " used, " +
           std::to_string(s.units_needed) + " needed for limits within " +
           Num(100 * o.width_margin) +
           " % of those of a known spread (teach anyway with allow_few_units, "
           "`eol teach --allow-few-units`)";
  s.few_units_forced = true;
  return "";
}

// The known-bad units that pass every scalar bound at the current weights; which bounds caught
// the others (by_lo, by_hi per scalar statistic, when given).
std::vector<std::string> KnownBadEscapes(const std::vector<GoldenUnit>& known_bad,
                                         const std::vector<Stat>& stats, std::size_t scalar_count,
                                         Budget& budget, std::vector<bool>* by_lo,
                                         std::vector<bool>* by_hi) {
  std::vector<std::string> out;
  for (const GoldenUnit& u : known_bad) {
    bool caught = false;
    for (std::size_t i = 0; i < scalar_count; ++i) {
      const Stat& st = stats[i];
      const double v = u.values.at(st.t.name);
      const bool lo = st.want_lo && v < budget.Lo(st, st.w_lo);
      const bool hi = st.want_hi && v > budget.Hi(st, st.w_hi);
      if (by_lo && lo) (*by_lo)[i] = true;
      if (by_hi && hi) (*by_hi)[i] = true;
      caught = caught || lo || hi;
    }
    if (!caught) out.push_back(u.label);
  }
  return out;
}

// The weight the known-bad units' donors may give (teach.h "Known-bad units"): defect-side
// scalar bounds that catch none of them, down to plausibility. Applies `scale_down` to their
// weights instead (naming them in *donors) when that is given.
double DonorWeight(std::vector<Stat>& stats, std::size_t scalar_count, std::size_t f0,
                   const std::vector<bool>& by_lo, const std::vector<bool>& by_hi,
                   double max_donation, const double* scale_down,
                   std::vector<std::string>* donors) {
  double movable = 0.0;
  auto give = [&](const Stat& st, double& w, const char* side) {
    if (!scale_down) {
      movable += max_donation * std::max(0.0, w - kPlausibilityWeight);
    } else if (w > kPlausibilityWeight) {
      w = kPlausibilityWeight + (w - kPlausibilityWeight) * *scale_down;
      donors->push_back(st.t.name + side);
    }
  };
  for (std::size_t i = 0; i < scalar_count; ++i) {
    Stat& st = stats[i];
    if (i != f0 && st.want_lo && st.defect_lo && !by_lo[i]) give(st, st.w_lo, " lo");
    if (st.want_hi && st.defect_hi && !by_hi[i]) give(st, st.w_hi, " hi");
  }
  return movable;
}

// Known-bad units (teach.h): the f0 lower bound takes as much of the donors' share as makes it
// catch every escape it can.
void MoveShareToF0(TeachSummary& s, std::vector<Stat>& stats, std::size_t scalar_count,
                   const std::vector<GoldenUnit>& known_bad, const TeachOptions& o,
                   bool f0_normalised, Budget& budget) {
  // The resonance's lower bound that carries the defect share: the pressure-normalised one
  // when it is declared.
  const std::string_view f0_name =
      f0_normalised ? names::kResonanceFRefPressureHz : names::kResonanceFHz;
  std::size_t f0 = scalar_count;
  for (std::size_t i = 0; i < scalar_count; ++i)
    if (stats[i].t.name == f0_name && stats[i].want_lo) f0 = i;
  std::vector<bool> by_lo(scalar_count, false), by_hi(scalar_count, false);
  s.known_bad_units = static_cast<int>(known_bad.size());
  s.known_bad_escapes_budget =
      KnownBadEscapes(known_bad, stats, scalar_count, budget, &by_lo, &by_hi);
  if (f0 < scalar_count) {
    Stat& f = stats[f0];
    s.f0_lo_budget_hz = budget.Lo(f, f.w_lo);
    const double movable = DonorWeight(stats, scalar_count, f0, by_lo, by_hi,
                                       o.known_bad_max_donation, nullptr, nullptr);
    // The highest f0 among the escapes the whole movable share can still catch.
    double target = -INFINITY;
    const double reach = budget.Lo(f, f.w_lo + movable);
    for (const GoldenUnit& u : known_bad)
      if (std::find(s.known_bad_escapes_budget.begin(), s.known_bad_escapes_budget.end(),
                    u.label) != s.known_bad_escapes_budget.end()) {
        // A margin of 1e-5 (relative) keeps the unit caught after Round6 writes the limit.
        const double v = u.values.at(f.t.name) * (1.0 + 1e-5);
        if (v < reach) target = std::max(target, v);
      }
    if (std::isfinite(target) && movable > 0.0) {
      double lo = 0.0, hi = movable;  // weight moved: Lo(w + hi) > target
      for (int it = 0; it < 50; ++it) {
        const double mid = 0.5 * (lo + hi);
        (budget.Lo(f, f.w_lo + mid) > target ? hi : lo) = mid;
      }
      // Each donor gives the same fraction of what it may give.
      const double moved = hi, scale_down = 1.0 - o.known_bad_max_donation * moved / movable;
      DonorWeight(stats, scalar_count, f0, by_lo, by_hi, o.known_bad_max_donation, &scale_down,
                  &s.known_bad_donors);
      f.w_lo += moved;
      s.known_bad_moved_share = budget.Share(moved);
    }
    s.f0_lo_hz = budget.Lo(f, f.w_lo);
  }
  s.known_bad_escapes = KnownBadEscapes(known_bad, stats, scalar_count, budget, nullptr, nullptr);
}

// Every statistic's bounds at its final share, and the bounds taught.
void SetBounds(TeachSummary& s, std::vector<Stat>& stats, Budget& budget) {
  const bool even = budget.even;
  for (Stat& st : stats) {
    const double share_lo = even ? 0.0 : budget.Share(st.w_lo);
    const double share_hi = even ? 0.0 : budget.Share(st.w_hi);
    st.k_lo = even ? s.k_factor : (st.want_lo ? budget.Factor(share_lo) : 0.0);
    st.k_hi = even ? s.k_factor : (st.want_hi ? budget.Factor(share_hi) : 0.0);
    st.t.lo = st.t.centre - st.k_lo * st.t.scale;
    st.t.hi = st.t.centre + st.k_hi * st.t.scale;
    const double even_share = 2.0 * budget.alpha / s.bounds;
    if (st.want_lo)
      s.taught_bounds.push_back(TaughtBound{st.t.name, true, st.defect_lo,
                                            even ? even_share : share_lo, st.k_lo, st.t.lo});
    if (st.want_hi)
      s.taught_bounds.push_back(TaughtBound{st.t.name, false, st.defect_hi,
                                            even ? even_share : share_hi, st.k_hi, st.t.hi});
  }
}

// The declared limits with the learned bounds (the statistics in *s too).
void WriteLimits(TeachSummary& s, const std::vector<MeasurementSpec>& declared,
                 const std::vector<Stat>& stats, double marginal_scales) {
  for (std::size_t i = 0; i < declared.size(); ++i) {
    const TaughtStatistic& t = stats[i].t;
    MeasurementSpec spec = declared[i];
    if (spec.limit.lo) spec.limit.lo = Round6(t.lo);
    if (spec.limit.hi) spec.limit.hi = Round6(t.hi);
    spec.limit.marginal = Round6(marginal_scales * t.scale);
    s.limits.push_back(spec);
  }
  for (const Stat& st : stats) s.statistics.push_back(st.t);
}

// Each run's mask: two points per segment (its first and last line) with its flat band.
std::string WriteMasks(TeachSummary& s, const std::vector<Run>& runs, const Frf& grid,
                       const std::vector<Stat>& stats, std::size_t scalar_count,
                       const TeachOptions& o) {
  std::size_t next = scalar_count;
  for (const Run& run : runs) {
    const std::size_t lines = run.b - run.a, segs = run.segments;
    CurveMask mask;
    mask.name = run.name;
    mask.quantity = MaskQuantity::kReOhm;
    mask.guard_sigma = o.mask_guard_sigma;
    mask.max_lines_outside = 0;
    for (std::size_t g = 0; g < segs; ++g, next += 2) {
      const std::size_t a = run.a + g * lines / segs, b = run.a + (g + 1) * lines / segs;
      double hi_v = Round6(stats[next].t.hi), lo_v = Round6(stats[next + 1].t.lo);
      if (!(hi_v > lo_v)) hi_v = lo_v + 1e-6;  // degenerate (no spread): keep the mask valid
      for (std::size_t k : {a, b - 1})
        mask.points.push_back(MaskPoint{grid.freq_hz[k], lo_v, hi_v});
    }
    std::string why;
    if (!mask.IsValid(&why)) return "taught mask " + mask.name + " is not valid: " + why;
    s.masks.push_back(mask);
  }
  return "";
}

// The summary's sentence: what was used, the budget, the expected false rejects, the units
// needed, the masks and the known-bad units.
std::string Message(const TeachSummary& s, const TeachOptions& o, const std::string& mask_note) {
  const double alpha = 1.0 - o.coverage;
  const std::string budget = o.allocation == "even"
                                 ? std::to_string(s.bounds) + " bounds (" + Num(s.p_bound) +
                                       " each): k = " + Num(s.k_factor)
                                 : std::to_string(s.bounds) +
                                       " bounds, shared by physics (largest share " +
                                       Num(1.0 - s.p_bound) + ": k = " + Num(s.k_factor) + ")";
  std::string m = std::string("method ") + ToString(o.method) + ", allocation " + o.allocation +
                  ", " + std::to_string(s.units_used) + " of " + std::to_string(s.units_given) +
                  " golden units used (" + std::to_string(s.rejected.size()) +
                  " rejected as outliers), false-reject target " + Num(100 * alpha) + " % over " +
                  budget + " at confidence " + Num(o.confidence) + "; expected false rejects " +
                  Num(100 * s.expected_false_reject) + " % (" + Num(100 * o.confidence) +
                  " % interval " + Num(100 * s.false_reject_lo) + "-" +
                  Num(100 * s.false_reject_hi) + " %); " + std::to_string(s.units_needed) +
                  " units needed for limits within " + Num(100 * o.width_margin) +
                  " % of a known spread (" + std::to_string(s.units_needed_distribution_free) +
                  " distribution-free)" + mask_note;
  if (s.known_bad_units > 0) {
    m += "; known-bad units: " + std::to_string(s.known_bad_units) + ", " +
         std::to_string(s.known_bad_escapes_budget.size()) +
         " pass the limits the budget alone sets";
    if (s.known_bad_moved_share > 0.0)
      m += ", f0 lower bound raised from " + Num(s.f0_lo_budget_hz) + " to " + Num(s.f0_lo_hz) +
           " Hz by moving share " + Num(s.known_bad_moved_share) +
           " of the budget from bounds that catch none of them (" +
           std::to_string(s.known_bad_donors.size()) + ")";
    m += ", " + std::to_string(s.known_bad_escapes.size()) + " pass the taught limits";
    if (!s.known_bad_escapes.empty())
      m += " (no bound within the budget catches them: " + s.known_bad_escapes.front() +
           (s.known_bad_escapes.size() > 1 ? ", ..." : "") + ")";
  }
  if (s.few_units_forced)
    m += "; WARNING: taught from fewer golden units than needed (forced), the limits are wide";
  return m;
}

}  // namespace

static TeachSummary TeachOnValues(const std::vector<MeasurementSpec>& declared,
                                  const std::vector<GoldenUnit>& golden, const TeachOptions& o,
                                  const std::vector<GoldenUnit>& known_bad) {
  TeachSummary s;
  s.units_given = static_cast<int>(golden.size());
  if (const std::string why = CheckInputs(declared, golden, o, known_bad); !why.empty())
    return Fail(s, why);
  const bool robust = o.method == TeachMethod::kMad;
  const bool f0_normalised = std::any_of(
      declared.begin(), declared.end(),
      [](const MeasurementSpec& d) { return d.name == names::kResonanceFRefPressureHz; });

  const std::vector<const GoldenUnit*> used =
      DropOutliers(declared, golden, o.outlier_z, &s.rejected);
  s.units_used = static_cast<int>(used.size());
  const double n = static_cast<double>(used.size());
  Budget budget;
  budget.n_eff = robust ? kMadEfficiency * n : n;
  if (budget.n_eff < 2.0 || used.size() < 3)
    return Fail(s, "too few golden units: " + std::to_string(used.size()) + " used of " +
                       std::to_string(golden.size()) +
                       (robust ? " (method mad needs at least 6)" : " (at least 3 needed)"));

  std::string mask_note;
  const std::vector<Run> runs = MaskRuns(used, o, &mask_note);
  std::vector<Stat> stats;
  if (const std::string why = ScalarStats(declared, used, robust, f0_normalised, &stats);
      !why.empty())
    return Fail(s, why);
  const std::size_t scalar_count = stats.size();
  AddMaskStats(runs, used, robust, &stats);

  if (const std::string why = SetBudget(s, stats, o, robust, &budget); !why.empty())
    return Fail(s, why);
  if (!known_bad.empty())
    MoveShareToF0(s, stats, scalar_count, known_bad, o, f0_normalised, budget);
  SetBounds(s, stats, budget);
  WriteLimits(s, declared, stats, o.marginal_scales);
  if (!runs.empty())
    if (const std::string why = WriteMasks(s, runs, used.front()->curve, stats, scalar_count, o);
        !why.empty())
      return Fail(s, why);
  ExpectedFalseReject(s, used.size(), o.confidence);
  s.usable = true;
  s.message = Message(s, o, mask_note);
  return s;
}

// The measurement's distribution (teach.h): measurements not about normal are taught on the
// scale where they are, ln(1 + x) or x^(1/3), and their limits brought back.
static bool InDomain(names::GoodSpread g, double x) {
  switch (g) {
    case names::GoodSpread::kLogOnePlus:
      return x > -1.0;
    case names::GoodSpread::kGamma:
      return x >= 0.0;
    case names::GoodSpread::kNormal:
      break;
  }
  return true;
}

static double ToTeachingScale(names::GoodSpread g, double x) {
  if (!InDomain(g, x)) return std::nan("");
  switch (g) {
    case names::GoodSpread::kLogOnePlus:
      return std::log1p(x);
    case names::GoodSpread::kGamma:
      return std::cbrt(x);
    case names::GoodSpread::kNormal:
      break;
  }
  return x;
}

static double FromTeachingScale(names::GoodSpread g, double y) {
  switch (g) {
    case names::GoodSpread::kLogOnePlus:
      return std::expm1(y);
    case names::GoodSpread::kGamma:
      return y * y * y;
    case names::GoodSpread::kNormal:
      break;
  }
  return y;
}

static const char* TeachingScaleName(names::GoodSpread g) {
  switch (g) {
    case names::GoodSpread::kLogOnePlus:
      return "ln(1 + x)";
    case names::GoodSpread::kGamma:
      return "x^(1/3): gamma";
    case names::GoodSpread::kNormal:
      break;
  }
  return "x";
}

// "" or the first unit whose value lies outside its measurement's family (a negative chi2).
static std::string OutsideFamily(const std::vector<MeasurementSpec>& declared,
                                 const std::vector<GoldenUnit>& units, const char* which) {
  for (const GoldenUnit& u : units)
    for (const MeasurementSpec& d : declared) {
      const names::GoodSpread g = names::GoodSpreadOf(d.name);
      const auto it = u.values.find(d.name);
      if (it != u.values.end() && std::isfinite(it->second) && !InDomain(g, it->second))
        return std::string(which) + " unit " + u.label + ": " + d.name + " = " + Num(it->second) +
               (g == names::GoodSpread::kGamma ? " is negative" : " is -1 or less") +
               ", outside the distribution teach learns it in (" + TeachingScaleName(g) +
               ", analysis/qc/measurement_names.h)";
    }
  return "";
}

static std::vector<GoldenUnit> ToTeachingScale(std::vector<GoldenUnit> units) {
  for (GoldenUnit& u : units)
    for (auto& [name, v] : u.values) v = ToTeachingScale(names::GoodSpreadOf(name), v);
  return units;
}

// The limits back on the measurement's own scale (the marginal band keeps its place inside the
// upper bound, or the lower one when there is no upper).
static void FromTeachingScale(TeachSummary& s) {
  for (MeasurementSpec& m : s.limits) {
    const names::GoodSpread g = names::GoodSpreadOf(m.name);
    if (g == names::GoodSpread::kNormal) continue;
    const double marginal = m.limit.marginal;
    const auto back = [&](double y) { return FromTeachingScale(g, y); };
    if (m.limit.hi) {
      m.limit.marginal = Round6(back(*m.limit.hi) - back(*m.limit.hi - marginal));
    } else if (m.limit.lo) {
      m.limit.marginal = Round6(back(*m.limit.lo + marginal) - back(*m.limit.lo));
    }
    if (m.limit.hi) m.limit.hi = Round6(back(*m.limit.hi));
    if (m.limit.lo) m.limit.lo = Round6(back(*m.limit.lo));
  }
  for (TaughtBound& b : s.taught_bounds)
    b.limit = FromTeachingScale(names::GoodSpreadOf(b.statistic), b.limit);
  for (TaughtStatistic& t : s.statistics) {
    const names::GoodSpread g = names::GoodSpreadOf(t.name);
    if (g != names::GoodSpread::kNormal)
      t.name += std::string(" (taught on ") + TeachingScaleName(g) + ")";
  }
}

// The pressure-normalised resonance (f0_pressure.h): fitted when f0 has a lower limit and every
// golden unit carries its clamp pressure; declared (with the f0 limit's unit) when used.
static F0PressureFit FitF0Pressure(const std::vector<MeasurementSpec>& declared,
                                   const std::vector<GoldenUnit>& golden,
                                   std::optional<MeasurementSpec>* spec) {
  F0PressureFit fit;
  const auto f0_spec = std::find_if(declared.begin(), declared.end(), [](const MeasurementSpec& d) {
    return d.name == names::kResonanceFHz && d.limit.lo;
  });
  if (f0_spec == declared.end()) {
    fit.note = "not used: the recipe has no lower limit on resonance_f_hz";
    return fit;
  }
  std::vector<std::pair<double, double>> f0_and_pressure;
  int without = 0;
  std::string first_without;
  for (const GoldenUnit& u : golden) {
    const auto f0 = u.values.find(std::string(names::kResonanceFHz));
    const auto p = u.values.find(std::string(names::kClampPressureBar));
    if (f0 == u.values.end() || p == u.values.end() || !std::isfinite(f0->second) ||
        !std::isfinite(p->second) || !(f0->second > 0.0) || !(p->second > 0.0)) {
      if (without++ == 0) first_without = u.label;
      continue;
    }
    f0_and_pressure.emplace_back(f0->second, p->second);
  }
  if (without > 0) {
    fit.note = "not used: " + std::to_string(without) + " of " + std::to_string(golden.size()) +
               " golden units carry no clamp pressure (first: " + first_without +
               "; station records carry it, `eol analyze --clamp-pressure-bar P --json` adds it)";
    return fit;
  }
  fit = TeachF0Pressure(f0_and_pressure);
  if (fit.definition) {
    MeasurementSpec m;
    m.name = std::string(names::kResonanceFRefPressureHz);
    m.unit = f0_spec->unit;
    m.doc =
        "first torsional mode at the reference clamp pressure, f0 (p_ref / p)^m "
        "(analysis/qc/f0_pressure.h)";
    m.limit.lo = f0_spec->limit.lo;
    *spec = m;
  }
  return fit;
}

// A declared bond index is taught first: its exponent and references from the golden units'
// f0 and residue (bond_index.h), then its value is added to every unit and it is taught as
// any other measurement. So is the pressure-normalised resonance, when the golden units' f0
// follows their clamp pressure (FitF0Pressure; a limit on it declared by an earlier teaching is
// taught afresh or dropped). Measurements not about normal are taught on their own scale (above).
TeachSummary TeachLimits(const std::vector<MeasurementSpec>& declared_in,
                         const std::vector<GoldenUnit>& golden, const TeachOptions& o,
                         const std::vector<GoldenUnit>& known_bad) {
  std::vector<MeasurementSpec> declared;
  for (const MeasurementSpec& d : declared_in)
    if (d.name != names::kResonanceFRefPressureHz) declared.push_back(d);
  std::optional<MeasurementSpec> f0_pressure_spec;
  const F0PressureFit f0_pressure = FitF0Pressure(declared, golden, &f0_pressure_spec);
  if (f0_pressure_spec) declared.push_back(*f0_pressure_spec);
  const bool index_declared =
      std::any_of(declared.begin(), declared.end(),
                  [](const MeasurementSpec& d) { return d.name == names::kBondIndexPct; });
  std::optional<BondIndexDefinition> index;
  // The normalised resonance first: the bond index weighs it when it is used.
  const auto add_f0_at_ref_pressure = [&](std::vector<GoldenUnit> units) {
    if (f0_pressure.definition)
      for (GoldenUnit& u : units) {
        std::map<std::string, Estimate> values;
        for (const auto& [name, v] : u.values) values[name] = Estimate{v, 0.0};
        const auto p = u.values.find(std::string(names::kClampPressureBar));
        if (p == u.values.end()) continue;  // a known-bad unit without it is refused by name
        AddF0AtRefPressure(values, p->second, *f0_pressure.definition);
        const auto e = values.find(std::string(names::kResonanceFRefPressureHz));
        if (e != values.end()) u.values[e->first] = e->second.value;
      }
    return units;
  };
  const std::vector<GoldenUnit> golden_p = add_f0_at_ref_pressure(golden);
  if (index_declared) {
    const std::string f0_name(f0_pressure.definition ? names::kResonanceFRefPressureHz
                                                     : names::kResonanceFHz);
    const std::string a_name(names::kMotionalResidueOhmPerS);
    std::vector<std::pair<double, double>> f0_and_residue;
    for (const GoldenUnit& u : golden_p) {
      const auto f0 = u.values.find(f0_name);
      const auto a = u.values.find(a_name);
      if (f0 == u.values.end() || a == u.values.end() || !(f0->second > 0.0) ||
          !(a->second > 0.0) || !std::isfinite(f0->second) || !std::isfinite(a->second)) {
        TeachSummary s;
        s.units_given = static_cast<int>(golden.size());
        s.message = "golden unit " + u.label + " has no positive " + f0_name + " and " + a_name +
                    " to teach bond_index_pct from";
        return s;
      }
      f0_and_residue.emplace_back(f0->second, a->second);
    }
    index = TeachBondIndex(f0_and_residue, o.bond_residue_to_f0);
    index->f0_name = f0_name;
  }
  const auto prepared = [&](std::vector<GoldenUnit> units) {
    if (index)
      for (GoldenUnit& u : units) {
        std::map<std::string, Estimate> values;
        for (const auto& [name, v] : u.values) values[name] = Estimate{v, 0.0};
        if (const auto e = BondIndex(values, *index))
          u.values[std::string(names::kBondIndexPct)] = e->value;
      }
    return ToTeachingScale(std::move(units));
  };
  for (const auto& [units, which] : {std::pair{&golden, "golden"}, {&known_bad, "known-bad"}})
    if (std::string why = OutsideFamily(declared, *units, which); !why.empty()) {
      TeachSummary s;
      s.units_given = static_cast<int>(golden.size());
      return Fail(s, why);
    }
  TeachSummary s =
      TeachOnValues(declared, prepared(golden_p), o, prepared(add_f0_at_ref_pressure(known_bad)));
  FromTeachingScale(s);
  s.bond_index = index;
  s.f0_pressure = f0_pressure;
  return s;
}

}  // namespace eol::analysis
