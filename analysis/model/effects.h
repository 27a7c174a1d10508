// Unmodelled effects (analysis/README.md 5) as structural additions to the nominal network, for the
// sim-to-real gap diagnosis (analysis/gap/). Each effect has few parameters, an equation
// below and physical plausibility bounds that depend on the nominal and the band.
//
// Nominal networks (s = j w, w = 2 pi f):
//   impedance (motor_model.h):  Z0 = R + s L + Zm,   Zm = 1 / Ym,
//     Ym = s Cp + Gp + 1 / (s Lp)   (the motional parallel R-L-C, the mechanics seen through
//     T^2: Cp = J / T^2 = Q / (w0 Rp), Lp = T^2 / k = Rp / (Q w0), Gp = R_m / T^2 = 1 / Rp)
//   mobility (RigidShaftMobility): M0 = Omega / I = Kt / (J s + b) = g / (s + a).
//
// The corrected network, every effect at its place (absent effects drop out):
//   support  Ys = Gp + 1 / (s Lp c(s))                       rotor spring + damper (+ creep)
//            Ys' = 1 / (1/Ys + s Lp / (kappa (1 + j eta)))    fixture spring in series
//   coupled  Yb = 1 / (1 / (s C2) + 1 / (G2 + 1 / (s L2)))     second inertia J2 on k2 (c2)
//            at a node x of the support: Ys'' = 1 / (x / Ys' + 1 / (Ys' / (1 - x) + Yb))
//   motional Zm' = 1 / (s Cp + Ys'')
//   winding  Zw = R + dR + R a (f / 1 kHz)^2 + s L - s^2 L2^2 / (s L2 + R2)
//               + b L (w_r^(1 - n) (j w)^n - s)       (fractional, w_r = 2 pi 1 kHz)
//   mode     Z2 = H2 / (1 + Q2 (s/w2 + w2/s))
//   inside   Zi = Zw + Zm' + Z2                  (mobility: Zi = M0 + Z2)
//   stray    Zc = Zi / (1 + s C Zi)
//   measured Z  = Zc exp(-s tau)
//
// Effects and their parameters (names are the stable JSON names, SI units):
//   series_resistance   resistance_ohm dR: leads, contacts, winding temperature (copper
//                       +0.39 %/K): a flat offset of Re Z. Bounds -0.5 R <= dR <= 2 R.
//   channel_delay       delay_s tau: skew between the voltage and current channels or an
//                       anti-alias mismatch; Re Z shifts by about w^2 L tau. |tau| <= 0.25/f_hi.
//   stray_capacitance   capacitance_f C: winding and cable capacitance across the terminals;
//                       Im Z grows faster than w L. 0 < C, self-resonance 1/(2 pi sqrt(L C))
//                       at least 1.2 f_hi.
//   lossy_inductance    l2_h, corner_hz: eddy currents as an L2-R2 branch (the inductance is L
//                       at low frequency and L - L2 far above the corner R2 / (2 pi L2), where
//                       the resistance has risen by R2). 0 < L2 <= 0.9 L; corner fitted
//                       within [0.1 f_lo, 100 f_hi] (bounded).
//   fractional_inductance  inductance_share b, order n, match_hz f_m: eddy currents in
//                       laminations as a fractional-order (semi-)inductance
//                       Z_L = s L (1 - b) + K (j w)^n, K = b L w_m^(1 - n): the share b of L
//                       becomes a (semi-)inductance with the same |Z| at w_m = 2 pi f_m (phase
//                       n 90 deg, so Re Z rises as w^n and Im Z / w falls as w^(n - 1)), where
//                       the L2-R2 branch has one corner. L (1 - b), K and n are three free
//                       numbers (a measured curve fixes all three over a wide band); f_m only
//                       names K in a unit that reads as a share. The selection between them is by
//                       evidence (both have two parameters). 0 <= b <= 1 (b = 1: the whole
//                       inductance is the semi-inductance, Z_L = K (j w)^n, as in a voice coil;
//                       b is fitted on a logistic map so it may sit at 1), 0.3 <= n <= 0.98,
//                       f_m in [0.1 f_lo, 10 f_hi].
//   skin_effect         skin_r_rise_at_1khz a: skin/proximity effect below the skin-depth
//                       transition, R(f) = R (1 + a (f / 1 kHz)^2). 0 <= a <= 3.
//   fixture_compliance  k_fixture_ratio kappa = k_fixture / k_nominal, fixture_loss_factor eta:
//                       a massless spring at the shaft end in series with the nominal support
//                       (the motional peak moves down to f0 sqrt(kappa / (1 + kappa)), height
//                       and Q change). Only the series compliance is identifiable; with the
//                       rotor inertia J known, k_fixture_nm_per_rad = kappa J w0^2.
//                       The rotor's viscous loss factor at the loaded frequency f' is (f'/f0)/Q
//                       and the series springs share loss in proportion to their compliance,
//                       so eta = ((1 + kappa) - kappa f'/f0) / Q keeps the nominal Q (what
//                       analysis::ClampedRotor assumes); eta = 0 is a lossless fixture.
//                       0.02 <= kappa <= 1e5, 0 <= eta <= 0.3.
//   second_mode         f_hz, q, height_ohm (mobility: height_rad_per_s_per_a): an extra
//                       torsional degree of freedom (flexible coupling, a rotor part) as a
//                       further parallel R-L-C in series with the motional one (its modal
//                       term). f in [0.5 f_lo, 2 f_hi], 0.5 <= q <= 3000,
//                       0 < height <= 100 max|Z0|.
//   coupled_inertia     mass_ratio mu = J2 / J, f2_hz = sqrt(k2 / J2) / (2 pi) (J2 alone on its
//                       spring), q2 = sqrt(k2 J2) / c2, node_compliance_share x: a second
//                       inertia (coupling hub, fan, encoder disc) on a spring k2 with damper c2,
//                       hung on a node of the support: x = 0 at the rotor, where the torque
//                       acts; x > 0 a node between the rotor spring and the fixture (the shaft
//                       end), with the share x of the support's compliance between the rotor
//                       and the node (x = k / k_rotor; the support's damping is taken
//                       stiffness-proportional, so each part is (k/s + c) / share). Seen through
//                       T^2 its branch is the series of C2 = mu Cp with (G2 + 1 / (s L2)),
//                       L2 = 1 / (w2^2 C2), G2 = w2 C2 / q2. At x > 0 the node moves (1 - x)
//                       times the rotor in the first mode, so J2 loads it about (1 - x)^2 as
//                       much and its own mode rings against both springs. Unlike second_mode it is
//                       coupled to the measured mode: the first mode always moves down (to f0 /
//                       sqrt(1 + mu) when f2 >> f0, where Q rises by sqrt(1 + mu) and the peak
//                       height Rp stays; a fixture spring keeps Q and lowers the height with its
//                       loss) and the coupled mode rings above with its own anti-resonance at f2.
//                       1e-3 <= mu <= 10, f2 in [0.5 f_lo, 20 f_hi] (at the top J2 is rigid on
//                       its node over the band: an added inertia), 0.5 <= q2 <= 3000,
//                       0 <= x <= 0.95. second_mode remains the model of a mode that is not coupled
//                       to the measured one (another path, another part).
//   adhesive_creep      creep_lambda lambda: viscoelastic adhesive, the rotor compliance
//                       C(f) = C0 (1 - lambda log10(f / f0)), written causally as the power law
//                       c(s) = (s / w0)^(-n), n = lambda / ln 10 (the same real part to first
//                       order, plus the loss tan(n pi / 2) it must carry). 0 <= lambda <= 0.3.
// Mobility: only second_mode and channel_delay apply (there is no winding and, for the rigid
// shaft, no spring to load).
#pragma once

#include <complex>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "analysis/frf.h"
#include "analysis/model/motor_model.h"

namespace eol::analysis {

// Angular velocity per current of a rigid shaft on a viscous damper:
//   M(s) = Kt / (J s + b) = g / (s + a),   g = Kt / J (rad/s^2/A),  a = b / J (1/s).
struct RigidShaftMobility {
  double gain_rad_per_s2_per_a = 0.0;
  double damping_per_s = 0.0;

  std::complex<double> At(double f_hz) const;
};

// 1 / z as conj(z) / |z|^2. The network's impedances and admittances lie far inside
// 1e-150..1e150, where this is exact to rounding; std::complex's division goes through
// libgcc's range-scaled __divdc3, which was most of the gap diagnosis' run time.
inline std::complex<double> Reciprocal(std::complex<double> z) {
  const double n = z.real() * z.real() + z.imag() * z.imag();
  return {z.real() / n, -z.imag() / n};
}

// The network an effect modifies: the clamped motor's impedance or the rigid shaft's mobility.
struct NominalNetwork {
  Quantity quantity = Quantity::kImpedanceOhm;
  MotionalImpedance motional;  // impedance
  RigidShaftMobility rigid;    // mobility
  // Rotor inertia J_r (kg m^2) when known from the simulation or recipe, else 0. Used only to
  // express the fixture's stiffness ratio in N m/rad.
  double inertia_kg_m2 = 0.0;

  std::complex<double> At(double f_hz) const;
  bool IsValid(std::string* why) const;
  // Stiffness of the nominal support k = J w0^2 (N m/rad); 0 when J or f0 is unknown.
  double NominalStiffnessNmPerRad() const;
};

enum class EffectKind {
  kSeriesResistance,
  kChannelDelay,
  kStrayCapacitance,
  kLossyInductance,
  kSkinEffect,
  kFixtureCompliance,
  kSecondMode,
  kAdhesiveCreep,
  kCoupledInertia,
  kFractionalInductance,
};
inline constexpr int kEffectKindCount = 10;

const char* ToString(EffectKind kind);  // the stable name, e.g. "fixture_compliance"
std::optional<EffectKind> ParseEffectKind(std::string_view name);
// Every effect that applies to the quantity, in EffectKind order.
std::vector<EffectKind> EffectsFor(Quantity quantity);

// How one parameter is fitted and what values are physically plausible.
struct EffectParamSpec {
  std::string name;  // stable JSON name
  std::string unit;
  double lo = 0.0;  // plausibility bounds (inclusive), natural units
  double hi = 0.0;
  // Fitted as ln(value) (value > 0; also for parameters bounded below by 0, so a fit can
  // approach "no effect" but never cross to the unphysical sign); else as value / scale.
  bool log_scale = false;
  double scale = 1.0;  // typical magnitude, natural units
  // Fitted as logit((value - lo) / (hi - lo)) (with log_scale: of ln(value / lo) /
  // ln(hi / lo)): a parameter that must stay inside its bounds and may sit at one, as a
  // coupling that is rigid over the band (overrides scale).
  bool bounded = false;
  // A signed scale (a delay, a resistance step): the evidence's prior (effect_fit.h) is
  // log-uniform in |value| over six decades below the larger bound, each sign half, as for the
  // log-scaled parameters, instead of uniform over [lo, hi], which charges a small value
  // ln((hi - lo) / |value|)^2 more than a log-scaled one of the same size.
  bool signed_log_prior = false;
};

struct EffectSpec {
  EffectKind kind;
  std::string name;
  std::string equation;  // one line for reports
  std::vector<EffectParamSpec> params;
  double f_lo_hz = 0.0;  // the band the bounds were made for
  double f_hi_hz = 0.0;
};

// The parameters and their bounds for this nominal and band [f_lo_hz, f_hi_hz].
EffectSpec DescribeEffect(EffectKind kind, const NominalNetwork& nominal, double f_lo_hz,
                          double f_hi_hz);

// One effect with its parameter values, in EffectSpec::params order, natural units.
struct AppliedEffect {
  EffectKind kind;
  std::vector<double> params;
};

// True when every parameter is finite and inside its bounds and the cross-parameter rules
// hold (lossy_inductance: corner R2 / (2 pi L2) in [0.1 f_lo, 100 f_hi]); otherwise false with
// the first rule broken in *why ("k_fixture_ratio = 3e6 above 1e5").
bool IsPlausible(const EffectSpec& spec, const AppliedEffect& effect, std::string* why);

// The corrected network at one frequency (see the top of this file). Each kind may appear at
// most once; kinds that do not apply to the nominal's quantity are ignored.
std::complex<double> EvaluateNetwork(const NominalNetwork& nominal,
                                     std::span<const AppliedEffect> effects, double f_hz);
Frf EvaluateNetwork(const NominalNetwork& nominal, std::span<const AppliedEffect> effects,
                    const std::vector<double>& freq_hz);

// w_r^(1 - n) (j w)^n at f_hz, w_r = 2 pi 1 kHz: the fractional inductance's shape (H -> ohm).
// w_m^(1 - n) (j w)^n with w_m = 2 pi ref_hz (default 1 kHz).
std::complex<double> FractionalShape(double order, double f_hz, double ref_hz = 1000.0);

// The fixture_loss_factor that keeps the nominal Q for stiffness ratio kappa (see above).
double FixtureLossKeepingQ(double kappa, double q);

// Quantities derived from fitted parameters for reports (name, unit, value):
//   fixture_compliance: k_fixture_nm_per_rad (when J is known), f_loaded_hz;
//   coupled_inertia:    j2_kg_m2, k2_nm_per_rad (when J is known);
//   lossy_inductance:   r2_ohm.
struct DerivedParam {
  std::string name;
  std::string unit;
  double value = 0.0;
};
std::vector<DerivedParam> DeriveEffectParams(const NominalNetwork& nominal,
                                             const AppliedEffect& effect);

}  // namespace eol::analysis
