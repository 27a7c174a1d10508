// Excitation designed for time (issue 16): the shortest periodic multisine record whose
// Cramer-Rao bound on the resonance frequency, at the recipe's nominal motor, meets the
// precision the recipe requires, with the amplitude as high as the recipe's limits allow.
//
// Why amplitude and record length trade: with white channel noise s_u (V), s_i (A) rms per
// sample, P periods of N samples and line amplitude U_k (line_measurement.h),
//   sigma_k^2 = |Z_k|^2 / P (4 s_u^2 / (N U_k^2) + 4 s_i^2 |Z_k|^2 / (N U_k^2)),
// so sigma_k^2 is proportional to 1 / (P N U_k^2) = 1 / (record time x line power), and the
// bound on f0 (cramer_rao.h, F = sum 2 Re(J^H J) / sigma_k^2) to 1 / (U sqrt(T)): a record ten
// times shorter at sqrt(10) times the amplitude carries the same information. The line spacing
// does not enter as long as the mode is resolved (the bound counts the lines in the half-power
// band, each with the power the sparser grid concentrates on it): the spacing is set by
// resolution (lines_per_half_power_band lines across f0 / Q of the nominal mode), the length of
// the record by the bound.
//
// The amplitude: the peak voltage is the largest that keeps (a) the peak at most max_peak_v
// (the amplifier), (b) the rms voltage at most max_v_rms and the rms current at most max_a_rms
// (the winding's heating, where the recipe states them), (c) the current's peak at most
// kCurrentHeadroom of the DAQ's current full scale (the nominal motor's current waveform, I_k = U_k
// / Z_k, synthesised from the lines).
//
// When the shortest record (min_periods) meets the requirement with room to spare, the
// amplitude is lowered until it just meets it ("requirement"): beyond the time floor amplitude
// buys only precision, and a lower level heats less and stays further from nonlinearity.
//
// The record: periods >= min_periods (2 for the transient-aware estimator, which removes the
// start transient instead of waiting it out: transient_frf.h); the bound is computed for the
// whole record (the transient-aware estimator reaches it: std/CRB 1.01, analysis/README.md).
// Candidates: the largest spacing that resolves the mode (fs / n for a whole n), and halves of
// it; per candidate the fewest periods that meet the bound; the shortest record wins (a tie:
// the coarser grid, fewer lines to fit).
#pragma once

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

#include "analysis/model/motor_model.h"
#include "analysis/signal/multisine.h"

namespace eol::analysis {

// The peak current is kept at or below this share of the current channel's full scale.
inline constexpr double kCurrentHeadroom = 0.8;

struct ExcitationRequirement {
  double sigma_f0_hz = 0.0;        // required std(f0) at the nominal motor, Hz (> 0)
  double verdict_margin_hz = 0.0;  // optional (0: none): std(f0) also <= margin / margin_z
  double margin_z = 3.0;
  MotionalImpedance nominal;  // the good motor the recipe expects (all positive)
  double noise_v_rms = 0.0;   // the DAQ's channel noise per sample, V and A (> 0)
  double noise_a_rms = 0.0;
  double max_peak_v = 0.0;                                     // amplifier limit, V (> 0)
  double max_v_rms = std::numeric_limits<double>::infinity();  // heating limits, optional
  double max_a_rms = std::numeric_limits<double>::infinity();
  double current_full_scale_a = std::numeric_limits<double>::infinity();
  double lines_per_half_power_band = 2.0;
  std::size_t min_periods = 2;
  double max_record_s = 60.0;

  // The std(f0) the design must reach: sigma_f0_hz, or margin / z when that is smaller.
  double RequiredSigmaF0Hz() const;
  bool IsValid(std::string* why) const;
};

struct ExcitationCandidate {
  double line_spacing_hz = 0.0;
  std::size_t lines = 0;
  double peak_v = 0.0;
  // "max_peak_v", "max_v_rms", "max_a_rms", "current_full_scale", or "requirement" (lowered)
  std::string amplitude_limited_by;
  double v_rms = 0.0, a_rms = 0.0, current_peak_a = 0.0;  // at the nominal motor
  double sigma_f0_one_period_hz = 0.0;  // the bound for one period at this amplitude
  std::size_t periods = 0;              // the fewest that meet the requirement
  double record_s = 0.0;                // periods / line spacing
  double sigma_f0_hz = 0.0;             // the bound for the whole record
  bool meets = false;                   // within max_record_s
};

struct ExcitationDesign {
  bool usable = false;
  std::string message;  // why not, or a one-line summary
  double required_sigma_f0_hz = 0.0;
  ExcitationCandidate chosen;
  std::vector<ExcitationCandidate> candidates;
  // `base` with the chosen spacing and peak (band, sample rate and phases kept).
  MultisineOptions excitation;
};

// The design for the band, sample rate and phases of `base` (its spacing and peak are chosen
// here). Throws std::invalid_argument when the requirement or `base` is invalid.
ExcitationDesign DesignExcitationForTime(const MultisineOptions& base,
                                         const ExcitationRequirement& requirement);

// What an excitation drives through a motor: rms voltage, rms current and peak current (the
// period as designed, at its peak_v).
struct ExcitationDrive {
  double v_rms = 0.0, a_rms = 0.0, a_peak = 0.0;
};
ExcitationDrive DriveThrough(const MultisineOptions& excitation, const MotionalImpedance& motor);

// The bound on f0 (Hz) at the nominal motor for an excitation played for `periods` periods and
// analysed whole (NaN when the bound does not exist, e.g. too few lines).
double PredictedSigmaF0Hz(const MultisineOptions& excitation, std::size_t periods,
                          const ExcitationRequirement& requirement);
// The same for an excitation already designed (at its own peak).
double PredictedSigmaF0Hz(const Excitation& excitation, std::size_t periods,
                          const ExcitationRequirement& requirement);

}  // namespace eol::analysis
