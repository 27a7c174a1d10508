// Statistical tolerance intervals for learning limits from good units (teach.h).
//
// Two-sided normal tolerance interval: from n values with mean m and standard deviation s,
// [m - k s, m + k s] contains at least a proportion p (the coverage) of the population with
// confidence gamma. The factor is computed exactly (Odeh and Owen 1980; Krishnamoorthy and
// Mathew, "Statistical Tolerance Regions", 2009, eq. 2.3.4), not taken from a table:
//   gamma = 2 sqrt(n / (2 pi)) Int_0^inf Q_chi2( nu r(z)^2 / k^2 ; nu ) exp(-n z^2 / 2) dz,
//   nu = n - 1, r(z) solving Phi(z + r) - Phi(z - r) = p, Q_chi2 the chi-square upper tail,
// solved for k by bisection (gamma increases with k). Known values: k(30, 0.99, 0.95) = 3.350,
// and k -> z_{(1+p)/2} as n -> inf.
//
// One-sided normal tolerance bound: m - k s (or m + k s) bounds at least a proportion p of the
// population from below (above) with confidence gamma when
//   gamma = Int phi(x) Q_chi2( nu (z_p + x / sqrt(n))^2 / k^2 ; nu ) dx   over z_p + x/sqrt(n) > 0
//           + Phi(-z_p sqrt(n)),
// z_p = Phi^-1(p) (the noncentral-t statement k = t'_{gamma}(nu, z_p sqrt(n)) / sqrt(n) written
// as an integral over the sample mean; Krishnamoorthy and Mathew 2009, section 2.2). Known
// value: k1(30, 0.99, 0.95) = 3.0639; k1 -> z_p as n -> inf.
//
// Distribution-free (Wilks): the range [min, max] of n values covers p with confidence
// 1 - n p^(n-1) + (n-1) p^n; WilksUnitsNeeded is the smallest such n.
#pragma once

namespace eol::analysis {

// Standard normal CDF and its inverse (Newton on erfc, |error| < 1e-12 for p in (1e-300, 1)).
double NormalCdf(double x);
double NormalQuantile(double p);

// Regularised upper incomplete gamma Q(a, x) = Gamma(a, x) / Gamma(a) (series or continued
// fraction, Numerical Recipes 6.2); the chi-square upper tail is Q(nu / 2, x / 2).
double GammaQ(double a, double x);
double ChiSquareUpperTail(double x, double nu);

// The exact two-sided normal tolerance factor. n >= 2, coverage and confidence in (0, 1).
// Programmer errors (bad arguments) throw std::invalid_argument.
double ToleranceFactorTwoSided(double n, double coverage, double confidence);

// The exact one-sided normal tolerance factor. n >= 2, coverage and confidence in (0, 1).
double ToleranceFactorOneSided(double n, double coverage, double confidence);

// Smallest n >= 2 whose one-sided factor is within (1 + width_margin) of z_p.
int OneSidedUnitsNeeded(double coverage, double confidence, double width_margin);

// Smallest n >= 2 whose factor is within (1 + width_margin) of the known-distribution value
// z_{(1+p)/2}: how many good units make the learned limits at most that much wider than
// limits from a perfectly known spread.
int ToleranceUnitsNeeded(double coverage, double confidence, double width_margin);

// Smallest n for which [min, max] of n units covers `coverage` with `confidence`.
int WilksUnitsNeeded(double coverage, double confidence);

}  // namespace eol::analysis
