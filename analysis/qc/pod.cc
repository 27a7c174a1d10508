#include "analysis/qc/pod.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "analysis/qc/tolerance.h"

namespace eol::analysis {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;

double Cdf(PodLink link, double eta) {
  return link == PodLink::kLogit ? 1.0 / (1.0 + std::exp(-eta)) : NormalCdf(eta);
}
double Quantile(PodLink link, double p) {
  return link == PodLink::kLogit ? std::log(p / (1.0 - p)) : NormalQuantile(p);
}
double Density(PodLink link, double eta) {
  if (link == PodLink::kLogit) {
    const double e = std::exp(-std::abs(eta));
    return e / ((1.0 + e) * (1.0 + e));
  }
  return std::exp(-0.5 * eta * eta) / std::sqrt(2.0 * kPi);
}
// The probit's inverse Mills ratio phi(t) / Phi(t), finite where Phi(t) underflows (t < -30:
// the asymptotic series Phi(t) / phi(t) = (1 - 1/t^2 + 3/t^4 - ...) / |t|).
double InverseMills(double t) {
  if (t > -30.0) return Density(PodLink::kProbit, t) / NormalCdf(t);
  const double u = 1.0 / (t * t);
  return -t / (1.0 - u + 3.0 * u * u);
}
// ln F(eta) and ln(1 - F(eta)), finite in the far tails: a fit far from the data (the
// likelihood-ratio profile) must still see a slope there.
double LogCdf(PodLink link, double eta) {
  if (link == PodLink::kLogit)
    return eta > 0.0 ? -std::log1p(std::exp(-eta)) : eta - std::log1p(std::exp(eta));
  if (eta > -30.0) return std::log(NormalCdf(eta));
  const double u = 1.0 / (eta * eta);
  return -0.5 * eta * eta - std::log(-eta) - 0.5 * std::log(2.0 * kPi) +
         std::log(1.0 - u + 3.0 * u * u);
}
double LogSurvival(PodLink link, double eta) { return LogCdf(link, -eta); }

double ToX(PodScale scale, double a) { return scale == PodScale::kLog ? std::log(a) : a; }
double ToA(PodScale scale, double x) { return scale == PodScale::kLog ? std::exp(x) : x; }

struct Obs {
  double x;
  double h;
};

double LogLik(PodLink link, const std::vector<Obs>& d, double b0, double b1) {
  double l = 0.0;
  for (const Obs& o : d) {
    const double eta = b0 + b1 * o.x;
    l += o.h * LogCdf(link, eta) + (1.0 - o.h) * LogSurvival(link, eta);
  }
  return l;
}

// Score d l_i / d eta_i and Fisher weight E[-d2 l_i / d eta_i^2] = f^2 / (F (1 - F)) of one
// observation, in forms that stay exact in the tails (logit: h - F and F (1 - F); probit:
// through the inverse Mills ratio, f^2 / (F (1 - F)) = lambda(eta) lambda(-eta)).
void ScoreWeight(PodLink link, double eta, double h, double* score, double* weight) {
  if (link == PodLink::kLogit) {
    const double p = Cdf(link, eta);
    *score = h - p;
    *weight = Density(link, eta);  // = F (1 - F) for the logistic
    return;
  }
  const double up = InverseMills(eta), down = InverseMills(-eta);
  *score = h * up - (1.0 - h) * down;
  *weight = up * down;
}

// Maximises the profile likelihood over b1 > 0 with eta = q + b1 (x - x_p); returns l.
double ProfileLogLik(PodLink link, const std::vector<Obs>& d, double q, double xp, double b1) {
  auto l_of = [&](double b) { return LogLik(link, d, q - b * xp, b); };
  double l = l_of(b1);
  for (int it = 0; it < 200; ++it) {
    double g = 0.0, w = 0.0;
    for (const Obs& o : d) {
      double s = 0.0, wt = 0.0;
      const double dx = o.x - xp;
      ScoreWeight(link, q + b1 * dx, o.h, &s, &wt);
      g += s * dx;
      w += wt * dx * dx;
    }
    if (g == 0.0) break;
    // Far from the data the weights vanish (or underflow) and the Newton step is huge: it is
    // kept within a factor of 10 of b1 (b1 stays > 0), then halved towards b1 until l does not
    // fall.
    double next =
        w > 0.0 ? std::clamp(b1 + g / w, 0.1 * b1, 10.0 * b1) : (g < 0.0 ? 0.1 * b1 : 10.0 * b1);
    double l_next = l_of(next);
    for (int half = 0; half < 60 && !(l_next >= l); ++half) {
      next = 0.5 * (b1 + next);
      l_next = l_of(next);
    }
    if (!(l_next >= l)) break;
    const bool done = std::abs(next - b1) <= 1e-12 * std::max(1.0, std::abs(b1));
    b1 = next;
    l = l_next;
    if (done) break;
  }
  return l;
}

// Smallest x > x0 where g(x) >= 0 (g(x0) < 0), searched up to x0 + 1e3 span; +inf if none.
template <typename G>
double FirstCrossing(G g, double x0, double span) {
  double lo = x0, step = span / 16.0, hi = x0 + step;
  while (g(hi) < 0.0) {
    lo = hi;
    step *= 2.0;
    hi = lo + step;
    if (hi - x0 > 1e3 * span) return kInf;
  }
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (g(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

std::vector<Obs> ToObs(const std::vector<HitMiss>& data, PodScale scale) {
  std::vector<Obs> d;
  d.reserve(data.size());
  for (const HitMiss& h : data) d.push_back({ToX(scale, h.size), h.hit ? 1.0 : 0.0});
  return d;
}

// Scans the sizes into s (range, hits); returns false with s->message when a size is not
// finite and positive or the data cannot be fitted (no hits, no misses, no overlap).
bool ScanSizes(const std::vector<HitMiss>& data, PodSummary* s) {
  double miss_max = -kInf, hit_min = kInf, miss_min = kInf, hit_max = -kInf;
  s->size_min = kInf;
  s->size_max = -kInf;
  for (const HitMiss& h : data) {
    if (!std::isfinite(h.size) || h.size <= 0.0) {
      std::ostringstream m;
      m << "defect size " << h.size << ": must be finite and > 0";
      s->message = m.str();
      return false;
    }
    s->size_min = std::min(s->size_min, h.size);
    s->size_max = std::max(s->size_max, h.size);
    if (h.hit) {
      ++s->hits;
      hit_min = std::min(hit_min, h.size);
      hit_max = std::max(hit_max, h.size);
    } else {
      miss_max = std::max(miss_max, h.size);
      miss_min = std::min(miss_min, h.size);
    }
  }
  std::ostringstream m;
  if (s->hits == 0 || s->hits == s->units) {
    m << (s->hits == 0 ? "no hits" : "no misses") << " among " << s->units << " units (sizes "
      << s->size_min << "-" << s->size_max << "): POD(a) cannot be fitted";
    s->message = m.str();
    return false;
  }
  if (miss_max <= hit_min || hit_max <= miss_min) {
    m << "hits and misses do not overlap (misses at " << miss_min << "-" << miss_max << ", hits at "
      << hit_min << "-" << hit_max
      << "): the maximum likelihood estimate does not exist (MIL-HDBK-1823A: test units with "
         "sizes in between)";
    s->message = m.str();
    return false;
  }
  return true;
}

// The maximum likelihood estimate (b0, b1), its log-likelihood and the Fisher information
// of the last iteration's start.
struct MlEstimate {
  double b0 = 0.0, b1 = 0.0, l = 0.0;
  double i00 = 0.0, i01 = 0.0, i11 = 0.0;
  bool converged = false;
};

// Fisher scoring from (b0, 0), each step halved until the likelihood does not fall;
// *iterations counts the steps (max_iterations + 1 when it did not converge).
MlEstimate MaximiseLikelihood(PodLink link, const std::vector<Obs>& d, double b0,
                              int max_iterations, int* iterations) {
  MlEstimate e;
  e.b0 = b0;
  e.l = LogLik(link, d, e.b0, e.b1);
  for (*iterations = 1; *iterations <= max_iterations; ++*iterations) {
    double g0 = 0.0, g1 = 0.0;
    e.i00 = e.i01 = e.i11 = 0.0;
    for (const Obs& o : d) {
      double sc = 0.0, w = 0.0;
      ScoreWeight(link, e.b0 + e.b1 * o.x, o.h, &sc, &w);
      g0 += sc;
      g1 += sc * o.x;
      e.i00 += w;
      e.i01 += w * o.x;
      e.i11 += w * o.x * o.x;
    }
    const double det = e.i00 * e.i11 - e.i01 * e.i01;
    if (!(det > 0.0)) break;
    double d0 = (e.i11 * g0 - e.i01 * g1) / det, d1 = (e.i00 * g1 - e.i01 * g0) / det;
    double l_next = LogLik(link, d, e.b0 + d0, e.b1 + d1);
    for (int half = 0; half < 60 && !(l_next >= e.l); ++half) {
      d0 *= 0.5;
      d1 *= 0.5;
      l_next = LogLik(link, d, e.b0 + d0, e.b1 + d1);
    }
    if (!(l_next >= e.l)) break;
    e.b0 += d0;
    e.b1 += d1;
    const double gain = l_next - e.l;
    e.l = l_next;
    if (gain < 1e-12 &&
        std::abs(d0) + std::abs(d1) < 1e-9 * (1.0 + std::abs(e.b0) + std::abs(e.b1))) {
      e.converged = true;
      break;
    }
  }
  return e;
}

// a50, a90 and the a90/95 bounds (Wald and likelihood ratio) of the fitted s.
void FillSizes(PodLink link, const std::vector<Obs>& d, PodSummary* s) {
  const double b0 = s->b0, b1 = s->b1, l = s->log_likelihood;
  const PodScale scale = s->options.scale;
  const double q = Quantile(link, s->options.pod_level);
  const double x90 = (q - b0) / b1;
  s->a50 = ToA(scale, -b0 / b1);
  s->a90 = ToA(scale, x90);
  const double span = std::max(ToX(scale, s->size_max) - ToX(scale, s->size_min), 1e-9);
  const double z = NormalQuantile(s->options.confidence);
  // Wald: the lower band crosses pod_level.
  const double x_w = FirstCrossing(
      [&](double x) {
        const double var = s->cov00 + 2.0 * x * s->cov01 + x * x * s->cov11;
        return b0 + b1 * x - z * std::sqrt(std::max(var, 0.0)) - q;
      },
      x90, span);
  s->a90_95_wald = std::isfinite(x_w) ? ToA(scale, x_w) : kInf;
  // Likelihood ratio: the profile deviance reaches z^2 (chi2_1 at 2 gamma - 1). As a90' -> inf
  // the best curve through (a90', pod_level) flattens (b1 -> 0) and its likelihood tends to
  // that of one POD for every size, l_0; when 2 (l - l_0) stays within z^2 no a90' is excluded
  // (the data do not show at this confidence that POD rises with a) and the bound is +inf.
  const double share = static_cast<double>(s->hits) / s->units;
  const double l0 = s->hits * std::log(share) + (s->units - s->hits) * std::log1p(-share);
  double x_lr = kInf;
  if (2.0 * (l - l0) > z * z)
    x_lr = FirstCrossing(
        [&](double x) { return 2.0 * (l - ProfileLogLik(link, d, q, x, b1)) - z * z; }, x90, span);
  s->a90_95_lr = std::isfinite(x_lr) ? ToA(scale, x_lr) : kInf;
}

std::string UsableMessage(const PodSummary& s) {
  const PodOptions& options = s.options;
  std::ostringstream m;
  m << ToString(options.link) << " POD on " << (options.scale == PodScale::kLog ? "ln a" : "a")
    << " from " << s.units << " units (" << s.hits << " hits, sizes " << s.size_min << "-"
    << s.size_max << "): a50 " << s.a50 << ", a" << std::lround(100 * options.pod_level) << " "
    << s.a90 << ", a" << std::lround(100 * options.pod_level) << "/"
    << std::lround(100 * options.confidence) << " " << s.a90_95_lr << " (likelihood ratio), "
    << s.a90_95_wald << " (Wald)";
  if (!std::isfinite(s.a90_95_lr) || !std::isfinite(s.a90_95_wald))
    m << "; inf: the data do not bound a" << std::lround(100 * options.pod_level)
      << " from above at this confidence";
  else if (s.a90_95_lr > s.size_max)
    m << "; a" << std::lround(100 * options.pod_level) << "/"
      << std::lround(100 * options.confidence)
      << " lies beyond the largest size tested (extrapolated)";
  if (s.misses_beyond_a90_95 > 0)
    m << "; " << s.misses_beyond_a90_95 << " miss(es) at or beyond a"
      << std::lround(100 * options.pod_level) << "/" << std::lround(100 * options.confidence)
      << " (up to " << s.largest_miss_beyond << "): POD may not rise monotonically there";
  return m.str();
}

}  // namespace

bool PodOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (!(confidence > 0.5 && confidence < 1.0)) return fail("confidence: must lie in (0.5, 1)");
  if (!(pod_level > 0.0 && pod_level < 1.0)) return fail("pod_level: must lie in (0, 1)");
  if (max_iterations < 1) return fail("max_iterations: must be at least 1");
  return true;
}

double PodSummary::Pod(double a) const {
  return Cdf(options.link, b0 + b1 * ToX(options.scale, a));
}

double PodSummary::PodLowerWald(double a) const {
  const double x = ToX(options.scale, a);
  const double var = cov00 + 2.0 * x * cov01 + x * x * cov11;
  const double z = NormalQuantile(options.confidence);
  return Cdf(options.link, b0 + b1 * x - z * std::sqrt(std::max(var, 0.0)));
}

PodSummary FitPod(const std::vector<HitMiss>& data, const PodOptions& options) {
  std::string why;
  if (!options.IsValid(&why)) throw std::invalid_argument("PodOptions: " + why);
  PodSummary s;
  s.options = options;
  s.units = static_cast<int>(data.size());
  if (data.empty()) {
    s.message = "no hit/miss data";
    return s;
  }
  if (!ScanSizes(data, &s)) return s;

  const PodLink link = options.link;
  const std::vector<Obs> d = ToObs(data, options.scale);
  const MlEstimate e =
      MaximiseLikelihood(link, d, Quantile(link, static_cast<double>(s.hits) / s.units),
                         options.max_iterations, &s.iterations);
  if (!e.converged) {
    std::ostringstream m;
    m << "the maximum likelihood fit did not converge in " << options.max_iterations
      << " iterations (b0 " << e.b0 << ", b1 " << e.b1 << ")";
    s.message = m.str();
    return s;
  }
  // Covariance at the estimate (the information of the last iteration's start is that of the
  // converged point up to the last, vanishing step).
  const double det = e.i00 * e.i11 - e.i01 * e.i01;
  s.b0 = e.b0;
  s.b1 = e.b1;
  s.cov00 = e.i11 / det;
  s.cov01 = -e.i01 / det;
  s.cov11 = e.i00 / det;
  s.log_likelihood = e.l;
  if (!(e.b1 > 0.0)) {
    std::ostringstream m;
    m << "POD does not rise with the defect size (b1 = " << e.b1 << ")";
    s.message = m.str();
    return s;
  }
  FillSizes(link, d, &s);
  for (const HitMiss& h : data)
    if (!h.hit && h.size >= s.a90_95_lr) {
      ++s.misses_beyond_a90_95;
      s.largest_miss_beyond = std::max(s.largest_miss_beyond, h.size);
    }
  s.usable = true;
  s.message = UsableMessage(s);
  return s;
}

double PodProfileDeviance(const std::vector<HitMiss>& data, const PodSummary& fit, double a90) {
  if (!fit.usable) return kInf;
  const std::vector<Obs> d = ToObs(data, fit.options.scale);
  const double q = Quantile(fit.options.link, fit.options.pod_level);
  return 2.0 * (fit.log_likelihood -
                ProfileLogLik(fit.options.link, d, q, ToX(fit.options.scale, a90), fit.b1));
}

const char* ToString(PodLink link) { return link == PodLink::kLogit ? "logit" : "probit"; }
const char* ToString(PodScale scale) { return scale == PodScale::kLog ? "log" : "linear"; }

PodLink ParsePodLink(const std::string& name) {
  if (name == "logit") return PodLink::kLogit;
  if (name == "probit") return PodLink::kProbit;
  throw std::invalid_argument("link: unknown value '" + name + "' (accepted: logit, probit)");
}

PodScale ParsePodScale(const std::string& name) {
  if (name == "linear") return PodScale::kLinear;
  if (name == "log") return PodScale::kLog;
  throw std::invalid_argument("scale: unknown value '" + name + "' (accepted: linear, log)");
}

nlohmann::json PodToJson(const PodSummary& s) {
  auto finite = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); };
  nlohmann::json j = {{"usable", s.usable},
                      {"message", s.message},
                      {"link", ToString(s.options.link)},
                      {"scale", ToString(s.options.scale)},
                      {"confidence", s.options.confidence},
                      {"pod_level", s.options.pod_level},
                      {"units", s.units},
                      {"hits", s.hits},
                      {"size_min", s.size_min},
                      {"size_max", s.size_max}};
  if (!s.usable) return j;
  j["b0"] = s.b0;
  j["b1"] = s.b1;
  j["covariance"] = {{s.cov00, s.cov01}, {s.cov01, s.cov11}};
  j["log_likelihood"] = s.log_likelihood;
  j["a50"] = s.a50;
  j["a90"] = s.a90;
  j["a90_95_lr"] = finite(s.a90_95_lr);
  j["a90_95_wald"] = finite(s.a90_95_wald);
  j["misses_beyond_a90_95"] = s.misses_beyond_a90_95;
  if (s.misses_beyond_a90_95 > 0) j["largest_miss_beyond"] = s.largest_miss_beyond;
  return j;
}

}  // namespace eol::analysis
