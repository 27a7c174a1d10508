// Several close motional modes (one soft magnet: a local mode beside the rotor mode,
// analysis/model/rotor_chain.h), found and fitted rather than averaged into one peak.
//
// Model, M modes, s = j w:
//   Z(f) = R + s L + sum_{n=1..M} Rp_n / (1 + Q_n (s/w_n + w_n/s)),   w_n = 2 pi f_n
// each mode a parallel R-L-C of motor_model.h; derivatives from motional_jacobian.h (the
// one place they live). Cost and residual as in resonance_fit.h: chi2 = sum_k 2 |Z_k -
// Z(f_k)|^2 / sigma_k^2 over K lines, parameters theta = ln(R, L, Rp_1, f_1, Q_1, ...).
//
// Procedure:
//   1. M = 1: FitMotionalResonance (resonance_fit.h), unchanged.
//   2. M -> M + 1: residual search. Over the (f, Q) grid of the options (coarse, then two
//      21 x 21 refinements around the best cell), with the M fitted (f_n, Q_n) held, the
//      linear parameters R, L, Rp_1..Rp_M and the new Rp are solved by weighted least
//      squares (variable projection); points with any of them <= 0, or within a quarter of a
//      half-power bandwidth of a fitted mode, are skipped. From the best point,
//      Levenberg-Marquardt (least_squares.h) on all 3 (M+1) + 2 log-parameters.
//   3. Model order: the M+1-mode fit is kept when it is usable (converged, finite covariance,
//      every f_n inside the search range, every Rp_n at least min_rp_significance standard
//      deviations, modes apart by more than 3 combined standard deviations of f) and lowers
//      the Bayesian information criterion
//        BIC = chi2 + p ln(2K)                    (sigma known; p = 3M + 2 parameters)
//        BIC = 2K ln(chi2_1 / 2K) + p ln(2K)       (no sigma: chi2_1 with unit weights)
//      i.e. with sigma known the extra mode must lower chi2 by more than 3 ln(2K) (~21 for
//      601 lines). Otherwise the search stops at M.
// Modes are reported in ascending frequency. With one mode the result is exactly
// FitMotionalResonance's (parameter names R_ohm, L_h, Rp_ohm, f0_hz, Q); with M >= 2 the names
// are R_ohm, L_h, Rp1_ohm, f1_hz, Q1, Rp2_ohm, f2_hz, Q2, ...
#pragma once

#include <complex>
#include <string>
#include <vector>

#include "analysis/fit/resonance_fit.h"

namespace eol::analysis {

struct MotionalMode {
  double rp_ohm = 0.0;
  double f0_hz = 0.0;
  double q = 0.0;
};

struct MultiModeImpedance {
  double r_ohm = 0.0;
  double l_h = 0.0;
  std::vector<MotionalMode> modes;

  std::complex<double> At(double f_hz) const;
};

struct ModesFitOptions {
  ResonanceFitOptions single;  // search range, Q range, grids, iterations, Rp significance
  int max_modes = 2;

  bool IsValid(std::string* why) const;
};

struct ModeOrderCandidate {
  int modes = 0;
  bool usable = false;
  double chi2 = 0.0;
  double bic = 0.0;
  std::string message;
};

struct ModesFitSummary {
  bool usable = false;  // the one-mode fit was usable (the selected order always is)
  std::string message;
  int mode_count = 0;
  FitSummary fit;  // the selected model (model "R+sL+<M>x parallel-RLC" when M >= 2)
  std::vector<ModeOrderCandidate> candidates;  // every order tried, ascending

  MultiModeImpedance Model() const;
};

// Never throws for bad data.
ModesFitSummary FitMotionalModes(const Frf& z, const ModesFitOptions& options);

}  // namespace eol::analysis
