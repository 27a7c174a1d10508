// The inputs of `eol gap`: a simulation and measured units, from whatever files they are in.
//
// Simulation (ReadGapSimulation), by content:
//   - an FRF file: FRF CSV (frf_files.h; plain or .gz) or .zma, taken as noise-free;
//   - a motor JSON (motor_json.h, recipes/motors/*.json): the clamped motor's torsional chain,
//     evaluated on the measured lines. J_r (for the fixture's stiffness in N m/rad) is the
//     rotor's inertia, magnets + poles + hub: the paper's given J_r. Not the modal inertia of
//     the chain's mode: with poorly cemented magnets the mode is mostly the magnets
//     (1/g ~ 3e-5 kg m^2) although the rotor, and how the fixture loads it, is unchanged;
//   - a rigid-shaft JSON (mobility), this file's format:
//       {"model": "rigid_shaft", "transmission_nm_per_a": Kt, "inertia_kg_m2": J,
//        "damping_nms_per_rad": b}      M = Kt / (J s + b)
//     or {"model": "rigid_shaft", "gain_rad_per_s2_per_a": g, "damping_per_s": a}
//       M = g / (s + a). Unknown keys are errors (io::ConfigError naming the JSON path).
// Measurement (ReadGapMeasurement), by content:
//   - an FRF file as above; without sigma the noise is estimated from the line-to-line scatter
//     (analysis/gap/noise.h) and the note says so; a sigma_dof column (frf_files.h) gives the
//     degrees of freedom of the file's sigma^2;
//   - a raw periodic recording, CSV with a t_s column (plain or .gz; text_table.h rules): the
//     input and output columns (defaults: impedance i_a -> u_v, Z = U / I; mobility
//     iq_a -> theta_motor_rad, H = j w Theta / I) through the periodic errors-in-variables
//     estimator (analysis/signal/periodic_frf.h; first period dropped). The period comes from
//     period_s, else is detected: the shortest whole divisor of the record (at least 3
//     periods) over which the input repeats (relative difference of consecutive periods
//     below 0.1 and within twice the best). Excited lines come from lines_file, else from
//     "<stem>-excited-lines-hz.txt" beside the recording (stem: the name up to its first
//     '.'), else are the bins whose input amplitude reaches 0.1 of the largest. sigma^2 then
//     has the estimator's 2 (P - 1) (2 h + 1) degrees of freedom (periodic_frf.h).
// Every error is a FileError or io::ConfigError naming the file (and line, or JSON path).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "analysis/frf.h"
#include "analysis/gap/tolerance.h"
#include "analysis/model/effects.h"

namespace eol::io {

struct GapInputOptions {
  analysis::Quantity quantity = analysis::Quantity::kImpedanceOhm;
  double period_s = 0.0;     // raw recordings: 0 = detect
  std::string input_column;  // raw recordings: "" = the quantity's default
  std::string output_column;
  std::string lines_file;  // raw recordings: excited lines in Hz, one per line
};

struct GapInput {
  analysis::Frf frf;
  std::string source;  // the path
  std::string kind;    // "frf-csv", "zma", "recording", "motor-json", "rigid-shaft-json"
  std::string note;    // how it was read (for the report)
  bool sigma_estimated = false;
  // Degrees of freedom of each line's sigma^2: the file's sigma_dof column or the periodic
  // estimator's; 0 when sigma is exact, unknown, or estimated by the reader.
  double sigma_dof = 0.0;
  // Simulations given as models: the exact nominal when the model is one (rigid shaft), and
  // the rotor inertia when the model knows it (0 otherwise).
  std::optional<analysis::NominalNetwork> model;
  double inertia_kg_m2 = 0.0;
  // The design's tolerances when the simulation states them (a motor JSON's "tolerances").
  std::optional<analysis::NominalTolerances> tolerances;
};

// `lines_hz`: where a model is evaluated (the measurement's lines); FRF files keep theirs.
GapInput ReadGapSimulation(const std::string& path, const GapInputOptions& options,
                           const std::vector<double>& lines_hz);
GapInput ReadGapMeasurement(const std::string& path, const GapInputOptions& options);

}  // namespace eol::io
