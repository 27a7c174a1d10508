// Probability of detection (POD) from hit/miss data, as MIL-HDBK-1823A (2009) states it
// (section 3.2 and appendix G, "hit/miss analysis"): `eol pod`, `eol production-bench`.
//
// Data: units i with a defect of known size a_i > 0 (here the bond stiffness loss, 0-1) and
// the station's verdict on each, hit h_i = 1 (rejected) or miss h_i = 0 (passed).
// Model (a generalised linear model):
//   POD(a) = F(b0 + b1 x),  x = a ("linear") or x = ln a ("log"),
//   F the logistic 1 / (1 + e^-eta) ("logit" link) or the normal CDF Phi ("probit").
// Estimator: maximum likelihood,
//   l(b) = sum_i h_i ln F(eta_i) + (1 - h_i) ln(1 - F(eta_i)),  eta_i = b0 + b1 x_i,
// by Fisher scoring (Newton for the logit) with step halving, from the flat curve at the hit
// share (b1 = 0). Its covariance is the inverse Fisher information
//   I = sum_i w_i [1 x_i; x_i x_i^2],  w_i = f(eta_i)^2 / (F (1 - F)),  f = F'.
// The maximum likelihood estimate exists only when hits and misses overlap in size: when
// every miss is smaller than every hit (or the reverse) the likelihood grows without bound
// as b1 -> inf; then the summary is not usable and says so (the handbook's remedy: more
// units near the transition).
// Points: a_p solves POD(a_p) = p, x_p = (F^-1(p) - b0) / b1; a50 and a90 are reported.
// Confidence on a90 (one-sided, level gamma = confidence, default 0.95: "a90/95"):
//   likelihood ratio (the handbook's method): a90/95 is the largest a90' whose profile
//     deviance 2 (l_max - max_{b1} l | x90 = x90') stays within chi2_1 quantile of 2 gamma - 1
//     (= z_gamma^2 = 2.706 for 95 %); the profile reparametrises eta = F^-1(0.9) + b1 (x - x90).
//   Wald: the lower confidence bound of the POD curve, F(eta(x) - z_gamma se(eta(x))),
//     se^2 = [1 x] I^-1 [1 x]^T, reaches 0.9 at a90/95 (the delta-method band).
// Either bound may not exist (the data do not bound a90 from above): then it is +inf and the
// summary says so; it stays usable for POD(a) and a90. For the LR bound that is the case when
// the deviance of the flat curve, 2 (l_max - l_0) with l_0 the likelihood of one POD for every
// size, stays within z_gamma^2: a90' -> inf tends to that curve, so no a90' is excluded.
#pragma once

#include <limits>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace eol::analysis {

struct HitMiss {
  double size = 0.0;  // defect size a (> 0; here the bond stiffness loss, 0-1)
  bool hit = false;   // the station rejected the unit
};

enum class PodLink { kLogit, kProbit };
enum class PodScale { kLinear, kLog };

struct PodOptions {
  PodLink link = PodLink::kLogit;
  PodScale scale = PodScale::kLinear;
  double confidence = 0.95;  // gamma, one-sided
  double pod_level = 0.90;   // the "90" of a90/95
  int max_iterations = 100;

  bool IsValid(std::string* why) const;
};

struct PodSummary {
  bool usable = false;
  std::string message;  // what was fitted, or why not (names the cause)
  PodOptions options;
  int units = 0, hits = 0;
  double size_min = 0.0, size_max = 0.0;
  int iterations = 0;
  double b0 = 0.0, b1 = 0.0;  // eta = b0 + b1 x
  double cov00 = 0.0, cov01 = 0.0, cov11 = 0.0;
  double log_likelihood = 0.0;
  double a50 = 0.0, a90 = 0.0;  // a at POD 0.5 and at pod_level
  double a90_95_lr = std::numeric_limits<double>::infinity();
  double a90_95_wald = std::numeric_limits<double>::infinity();
  // Misses at sizes at or beyond a90/95 (LR), and the largest such size: the model is monotone,
  // the data need not be (one soft magnet whose own mode meets the rotor's hides again).
  int misses_beyond_a90_95 = 0;
  double largest_miss_beyond = 0.0;

  // POD at size a and its one-sided lower Wald bound (confidence as fitted).
  double Pod(double a) const;
  double PodLowerWald(double a) const;
};

// Never throws for bad data: usable == false with the reason. Throws std::invalid_argument for
// invalid options (a programmer error).
PodSummary FitPod(const std::vector<HitMiss>& data, const PodOptions& options);

// The profile deviance of the LR method at a90' (0 at the estimate); +inf if not fitted.
double PodProfileDeviance(const std::vector<HitMiss>& data, const PodSummary& fit, double a90);

const char* ToString(PodLink link);
const char* ToString(PodScale scale);
PodLink ParsePodLink(const std::string& name);    // std::invalid_argument names the accepted
PodScale ParsePodScale(const std::string& name);  // values
nlohmann::json PodToJson(const PodSummary& s);    // infinite bounds as null

}  // namespace eol::analysis
