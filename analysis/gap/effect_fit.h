// Fitting unmodelled effects (analysis/model/effects.h) on top of the nominal network.
//
// The nominal's own parameters (NominalFit): kFixed keeps them at the simulation's values;
// kTolerance (the diagnosis' default) fits them with the effects under a Gaussian prior of the
// design's tolerances (tolerance.h): theta starts with the identifiable log-shifts d of the
// nominal (impedance: ln R, ln L, ln Rp, ln f0, ln Q; mobility: ln g, ln a), the residual gets
// the prior's rows W d, and the evidence integrates them out (below); kFree fits them with no
// prior (a calibration beyond the tolerances; no evidence). The effects' parameters are fitted
// on every (selected) line of every unit, from the normalised residual
//   r_uk = (H_meas(u,k) - H_model(f_uk)) / sigma_uk                 (impedance form)
//   r_uk = (1/H_meas - 1/H_model) |H_meas|^2 / sigma_uk             (admittance form)
// The admittance form is for a ratio Z = U / I whose current channel carries the noise: then
// 1/Z is linear in that noise and its sigma, sigma / |Z|^2 = s_I / |U|, does not depend on the
// noise draw, where sigma_Z (proportional to |Z_meas|^2) does and weights the lines whose
// current came out high: a bias of -eps/2 sigma per line along Z (eps = sigma/|Z|), which
// summed over hundreds of noisy lines looks like a lower inductance. Both forms agree to first
// order when eps is small. The form is chosen per line (ChooseResidualForm): a motor's |Z|
// rises with f, so one channel's noise can dominate the low lines and the other's the high.
//   chi2 = 2 sum |r_uk|^2   (the fit module's convention: 2K real residuals of unit variance)
//   cost = sum rho(|r_uk|^2),  rho(u) = (nu + 2) ln(1 + 2 u / nu)   (-2 ln L + const)
// With sigma^2 estimated on nu degrees of freedom (GapUnit::sigma_dof) r is a bivariate
// Student t, not Gaussian: rho is its -2 ln L, which keeps a single heavy-tailed line from
// buying a narrow mode; nu = 0 (exact sigma) gives rho = 2 u, the chi2. The fits minimise
// the cost (Levenberg-Marquardt on the residual scaled by sqrt(rho(u) / u)), and the model
// selection (diagnosis.h) scores it.
// Evidence: -2 ln p(data | effect) ~ cost + prior + occam. The nominal's shifts d under their
// Gaussian prior (covariance C) pay ln det(I + C A_nn) = ln det C + ln det(A_nn + C^-1) (A the
// information, A_nn its block for d: 0 for a shift the data leave to the prior, ln of
// (prior width / posterior width)^2 for one they pin), and the effects' parameters are charged
// on their information with d integrated out (the Schur complement A_ee - A_en (A_nn +
// C^-1)^-1 A_ne): an effect that only re-draws a calibration within the tolerances pins
// nothing the prior had not. For the effects' unbounded parameters (Laplace)
//   occam = sum_i max(0, ln(lambda_i / 2 pi)),  lambda_i the eigenvalues of W A W,
// A = J^T J the information in theta at the optimum and W the prior widths of the thetas
// (uniform in ln(value) over the plausibility bounds for log-scaled parameters, in ln |value|
// over six decades, each sign half, for signed scales such as a delay, in value for the
// others). A parameter the data pin down pays ln of (prior width / posterior width)^2; one
// they leave as open as its prior pays nothing (where BIC charges every parameter ln(2K)):
// an effect whose shape predicts a relation (a coupled inertia keeps the peak height while it
// lowers f0 and raises Q) is not charged for parameters the data do not need.
// A bounded parameter (fitted on the logistic map of its range, EffectParamSpec::bounded) may
// sit at a bound or have a likelihood flat over part of its range (a coupling rigid over the
// band: f2 anywhere above it), where Laplace sees no curvature and would charge nothing for
// the part of the prior the data exclude. Each is integrated over its prior (uniform in its
// share of the range) numerically instead, -2 ln of the likelihood's mean, in turn as the
// chain rule has it: the unbounded parameters and the bounded ones after it follow (one
// Gauss-Newton step within their ranges, the better of the two points evaluated in full), so a
// valley the data leave open (a rigid J2 at the rotor, or a heavier one at a node) is
// integrated along. For a Gaussian likelihood inside the range it is Laplace's
// ln(lambda / 2 pi).
// Of the local optima the starts reach, an effect is scored in the one of best evidence (a
// narrow basin that fits a few noisy lines pays for pinning its parameters).
// Parameters are fitted as ln(value) (positive, wide-ranging ones) or value / scale, with
// analysis::MinimizeLeastSquares (fit/least_squares.h: MINPACK Levenberg-Marquardt) on
// forward-difference Jacobians; the covariance (Jr^T Jr)^-1 at the optimum, from a central-
// difference Jacobian there,
// (fit/least_squares.h InvertInformation) is mapped to natural units to first order.
//
// Starting values (Starts) come from the residual against a base model (the nominal plus any
// effects already fitted, for pairs), mostly by variable projection: where an effect enters
// as amplitude c times a fixed shape B_k, dH ~ c B_k gives c by weighted linear least squares:
//   series_resistance B = 1;  channel_delay B = -s H;  stray_capacitance B = -s H^2;
//   skin_effect B = R (f / 1 kHz)^2;  lossy_inductance B = -s^2 / (s + w_c) on a grid of
//   corners w_c (c = L2, R2 = w_c L2);  second_mode B = 1 / (1 + j q x) on a grid of (f, q)
//   (c = height > 0);  fixture_compliance and adhesive_creep on a grid of their parameter.
// With the nominal calibrated, the stiffness and J calibration moves the first mode as a fixture
// spring, a coupled inertia or a creeping bond does, by up to 3-4 tolerances (f0 by 20-30 %).
// So an effect that moves the mode is also started where it is the whole shift: a single from
// the simulation's nominal (FitKinds), a pair's member from the other member's calibrated
// nominal with f0 put back at the simulation's (R, L and the peak stay calibrated, so the start
// grid scores the mode, not the tolerances). Without it a fixture spring beside a channel delay
// (the delay's nominal: stiffness at -3 tolerances) was found only as a stiff spring with a loss
// factor of 0.3-0.5 on top, rejected, and adhesive_creep named.
#pragma once

#include <complex>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "analysis/gap/tolerance.h"
#include "analysis/model/effects.h"

namespace eol::analysis {

// One measured unit, ready for the gap: every line has a positive sigma.
struct GapUnit {
  std::string name;
  std::vector<double> freq_hz;
  std::vector<std::complex<double>> value;
  std::vector<double> sigma;
  // Degrees of freedom of each sigma^2 (residual.h NoiseLine): 2 (P - 1) from P periods,
  // times the lines pooled; 0 when sigma is known exactly.
  double sigma_dof = 0.0;
  bool admittance = false;  // residual form (above); impedance quantity only
  // Per line (empty: `admittance` for every line): the admittance form on the lines whose
  // current channel carries most of the noise (CurrentNoiseLines), the impedance form on the
  // others.
  std::vector<bool> admittance_line;
  // sigma does not depend on the line's own noise draw (estimated from the line-to-line
  // scatter, or pooled over neighbours: noise.h): the impedance form is unbiased for it, and
  // the admittance form's |H_meas|^2 would bring the draw back; DiagnoseGap keeps impedance.
  bool sigma_smooth = false;

  std::size_t size() const { return freq_hz.size(); }
};

// The normalised complex residual r of line k against the model value h, in u's form.
std::complex<double> LineResidual(const GapUnit& u, std::size_t k, std::complex<double> h);
// rho(|r|^2) above for sigma^2 on sigma_dof degrees of freedom (0: exact).
double LineCost(double r2, double sigma_dof);
// Per line, whether the current channel carries most of the noise: eps_k^2 = a + b |H_k|^2
// (eps = sigma / |H|; a: the voltage channel's relative noise, flat in |H| under a flat
// excitation; b |H|^2: the current's) fitted to the lines by relative least squares with
// a, b >= 0, |H_k| the median of |H| over k +- 3; line k is the current's where
// b |H_k|^2 > a. There 1/H = I/U is linear in the dominant noise and unbiased, where H = U/I
// is biased low by about exp(-|I|^2 / s_I^2) (s_I: the mean current's noise) and its sigma
// follows the draw; on the voltage's lines the other way round.
std::vector<bool> CurrentNoiseLines(const GapUnit& u);

enum class ResidualForm { kAuto, kImpedance, kAdmittance };
// Sets the unit's residual form (GapUnit::admittance, admittance_line) for an impedance
// (mobility: always as measured). kAuto: the admittance form on CurrentNoiseLines, the
// impedance form on the others and on every line of a unit whose sigma is smooth
// (GapUnit::sigma_smooth); kAdmittance / kImpedance: every line.
void ChooseResidualForm(GapUnit& u, bool impedance_quantity, ResidualForm form);

// mask[u][k] != 0: line k of unit u takes part. An empty mask selects every line.
using LineMask = std::vector<std::vector<char>>;

enum class NominalFit { kFixed, kTolerance, kFree };

struct EffectFit {
  std::vector<AppliedEffect> effects;
  NominalNetwork nominal;  // the nominal the effects sit on (refitted unless kFixed)
  Eigen::VectorXd shift;   // its identifiable log-shifts d from the simulation's (empty: fixed)
  double prior = 0.0;      // d^T C^-1 d (kTolerance): minimised with the cost
  int n_nominal = 0;       // the nominal's own parameters fitted
  std::vector<std::vector<double>> sigma;  // per effect, per parameter, natural units (NaN:
                                           // not determined)
  double chi2 = 0.0;                       // on the selected lines
  double cost = 0.0;                       // sum rho (above), what the fit minimised
  double occam = 0.0;                      // the Laplace evidence's penalty (above)
  int residuals = 0;                       // 2 x selected lines
  int n_params = 0;                        // the effects' parameters
  bool converged = false;
  int iterations = 0;
  // FitKinds: the lowest-cost optimum's effects, kept when the answer is another basin with a
  // better evidence (empty otherwise); pairs start from it, where the fit of both is.
  std::vector<AppliedEffect> lowest_cost;
  NominalNetwork lowest_cost_nominal;  // the nominal that basin sits on

  // -2 ln of the evidence (above): what the basins and the candidates are compared by.
  double Evidence() const { return cost + prior + occam; }
};

class EffectFitter {
 public:
  // f_lo_hz, f_hi_hz: the band the plausibility bounds refer to (the units' band).
  EffectFitter(const NominalNetwork& nominal, const std::vector<GapUnit>& units);
  // The nominal's own parameters fitted as `mode` says (kTolerance: under `tolerances`).
  EffectFitter(const NominalNetwork& nominal, const std::vector<GapUnit>& units, NominalFit mode,
               const NominalTolerances& tolerances = {});
  // Where the nominal starts in Fit and the nominal Starts scores its grids on (default: the
  // simulation's; the diagnosis sets the calibrated one).
  void SetStartNominal(const NominalNetwork& n) { start_nominal_ = n; }
  NominalFit mode() const { return mode_; }
  const TolerancePrior* prior() const { return prior_.get(); }

  const NominalNetwork& nominal() const { return nominal_; }
  const std::vector<GapUnit>& units() const { return units_; }
  double f_lo_hz() const { return f_lo_; }
  double f_hi_hz() const { return f_hi_; }
  EffectSpec Spec(EffectKind kind) const { return DescribeEffect(kind, nominal_, f_lo_, f_hi_); }

  // chi2 of nominal + effects on the selected lines; *residuals gets 2 x lines when given.
  double Chi2(std::span<const AppliedEffect> effects, const LineMask& mask,
              int* residuals = nullptr) const;
  // cost (above) of nominal + effects on the selected lines.
  double Cost(std::span<const AppliedEffect> effects, const LineMask& mask) const;

  // Starting parameter vectors for `kind` on top of `base` (at most a few, best first).
  std::vector<std::vector<double>> Starts(EffectKind kind, std::span<const AppliedEffect> base,
                                          const LineMask& mask) const;

  // Levenberg-Marquardt from `start` (every parameter of every effect is free; the nominal's
  // as mode() says, from the start nominal).
  EffectFit Fit(const std::vector<AppliedEffect>& start, const LineMask& mask,
                int max_iterations) const;
  // The same from the nominal `from` in another mode.
  EffectFit FitFrom(const NominalNetwork& from, NominalFit mode,
                    const std::vector<AppliedEffect>& start, const LineMask& mask,
                    int max_iterations) const;

  // Calibration beyond the tolerances and structure together: FitFrom(nominal, kFree, ...),
  // the refitted nominal also in *refitted (start may be empty: a refit of the nominal alone).
  EffectFit FitWithNominal(const NominalNetwork& nominal, const std::vector<AppliedEffect>& start,
                           const LineMask& mask, int max_iterations,
                           NominalNetwork* refitted) const;
  // chi2 / cost of another nominal + effects on the selected lines (as Chi2 and Cost).
  double Chi2With(const NominalNetwork& nominal, std::span<const AppliedEffect> effects,
                  const LineMask& mask, double* cost = nullptr) const;

  // The best of the fits started from Starts(kind) for each kind in `kinds`, the kinds
  // fitted jointly; for a pair the second kind's starts are taken on top of `seeds` (the
  // kinds' single fits, same order as kinds) and vice versa. Best: of the plausible
  // (IsPlausible) converged fits the one of best evidence (cost + occam); when that is not the
  // lowest-cost one, the lowest-cost one is kept in lowest_cost. The lowest cost of all only
  // when no fit is plausible and converged.
  // seed_nominals: the nominal each seed's fit sat on (the pair's starts begin there; empty:
  // the start nominal). With the nominal calibrated, a single also starts from the
  // simulation's nominal (its two best starts there).
  EffectFit FitKinds(const std::vector<EffectKind>& kinds, const std::vector<AppliedEffect>& seeds,
                     const LineMask& mask, int max_iterations,
                     const std::vector<NominalNetwork>& seed_nominals = {}) const;

 private:
  // A dense curve (more than kScreenLines selected lines, e.g. an analyser's 10 000-line sweep)
  // scores FitKinds' start grids and fits its starts on every k-th of its lines (k = lines /
  // kScreenLines + 1), then refits only the kRefinedStarts best basins (plausible and converged
  // first, then evidence) on all of them, from the coarse optima: the basins are found on about
  // kScreenLines lines, the answer and its evidence are those of every line. Curves of
  // kScreenLines or fewer lines (every blind benchmark case) fit every start on every line.
  static constexpr long kScreenLines = 1500;
  static constexpr std::size_t kRefinedStarts = 3;
  using Start = std::pair<NominalNetwork, std::vector<AppliedEffect>>;  // nominal, effects
  bool Admissible(const EffectFit& f) const;  // plausible (IsPlausible) and converged
  long SelectedLines(const LineMask& mask) const;
  LineMask Thinned(const LineMask& mask, long step) const;
  std::vector<Start> Screened(std::vector<Start> starts, const LineMask& coarse,
                              int max_iterations) const;
  // FitKinds' starts for a pair: the seeds together, and each kind's starts on top of the other
  // kinds' seeds (at the other's nominal; a mode-moving kind also with f0 back at the
  // simulation's, "Starting values" above).
  std::vector<Start> PairStarts(const std::vector<EffectKind>& kinds,
                                const std::vector<AppliedEffect>& seeds, const LineMask& scan,
                                const std::vector<NominalNetwork>& seed_nominals) const;
  double CostAt(const NominalNetwork& at, std::span<const AppliedEffect> effects,
                const LineMask& mask) const;
  std::vector<std::vector<double>> StartsAt(EffectKind kind, std::span<const AppliedEffect> base,
                                            const LineMask& mask, const NominalNetwork& at) const;

  NominalNetwork nominal_;
  NominalNetwork start_nominal_;
  NominalFit mode_ = NominalFit::kFixed;
  std::shared_ptr<const TolerancePrior> prior_;
  std::vector<GapUnit> units_;
  double f_lo_ = 0.0, f_hi_ = 0.0;
};

bool Selected(const LineMask& mask, std::size_t unit, std::size_t line);

}  // namespace eol::analysis
