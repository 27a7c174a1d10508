// The sim-to-real gap diagnosis from its inputs (analysis/gap/diagnosis.h on the readers of
// drivers/io/gap_inputs.h) and its figure: one path for `eol gap` (files) and POST
// /api/gap.svg (uploads), so both read, diagnose and draw alike.
//
// Order: the measured units are read first and kept to the band [f_lo_hz, f_hi_hz]; a model
// simulation is evaluated on the first unit's lines. The nominal network is calibrated to the
// simulation with J_r = inertia_kg_m2, else the simulation's own (motor JSON), else, for an
// impedance, the recipe's rotor inertia (fallback_inertia_kg_m2); 0 leaves J_r unknown and the
// fixture is reported as a ratio.
//
// The figure (GapChart), drawn with drivers/io/chart.h over the first measured unit's lines:
//   impedance: Re Z and Im Z - w L_nominal (the motional part under the inductive background);
//   mobility:  |H| (log) and the phase of H in degrees;
// each with the measured unit (markers), the simulated (calibrated nominal, dashed) and the
// corrected curve (nominal + the diagnosed effect); below, |H_meas - H_model| / sigma of the
// simulated and corrected curves against 1 sigma. The bands where the gap is are shaded.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "drivers/io/chart.h"
#include "station/reports/gap_report.h"

namespace eol::station {

struct GapRunOptions {
  io::GapInputOptions io;
  double f_lo_hz = 0.0;  // keep lines at or above; 0: no limit
  double f_hi_hz = 0.0;  // keep lines at or below; 0: no limit
  // Pools each line's relative variance over +-N lines (files whose sigma rests on few periods).
  int sigma_pool = 0;
  // Degrees of freedom of each measured line's sigma^2 (2 (P - 1) from P periods, times the
  // lines pooled); 0: the measured file's own (its sigma_dof column, the periodic estimator's
  // for a raw recording, else read from the scatter of sigma itself: io::GapInput::sigma_dof),
  // times 2 sigma_pool + 1. A unit whose sigma was estimated by the reader takes 0.
  double sigma_dof = 0.0;
  bool sigma_exact = false;    // the files' sigma is exact (a noise model's): 0 for every unit
  double inertia_kg_m2 = 0.0;  // J_r given; 0: the simulation's, else the fallback
  double fallback_inertia_kg_m2 = 0.0;        // impedance only: the recipe's rotor inertia
  std::vector<analysis::EffectKind> effects;  // only these; empty: every effect
  bool try_pairs = true;
  // The nominal calibrated under the design's tolerances (analysis/gap/tolerance.h) in every
  // fit; false: kept at the simulation's values (--fixed-nominal).
  bool calibrate = true;
  // "name=value,..." over the simulation's tolerances (a motor JSON's), else the defaults
  // (--tolerances); a bad one throws std::invalid_argument naming it.
  std::string tolerances;
};

// The calibration or the diagnosis cannot be used (the message says why, naming the input).
class GapNotUsable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Keeps the lines in [lo, hi] (0: no limit).
void KeepBand(analysis::Frf* f, double lo, double hi);

// The nominal network calibrated to a simulation (exactly, when the simulation is a model).
analysis::CalibrationSummary CalibrateToSimulation(const io::GapInput& simulation,
                                                   double inertia_kg_m2);

// Reads the measured units and the simulation (paths, any format of gap_inputs.h) into
// report->measured and report->simulation, band kept. Throws io::FileError or io::ConfigError
// naming the file, also for a unit with fewer than 10 lines in the band.
void ReadGapInputs(const std::string& simulation, const std::vector<std::string>& measured,
                   const GapRunOptions& options, GapReport* report);

// Calibrates, diagnoses and compares features: fills report->calibration, ->gap, ->features
// and ->inertia_kg_m2 from the inputs ReadGapInputs read. Throws GapNotUsable.
void DiagnoseGapReport(const GapRunOptions& options, GapReport* report);

// An input given as the text of its file (the API's uploads); `name` is the file name the
// readers go by (.zma, .json; anything else is CSV). Text formats only (no .gz).
struct GapUpload {
  std::string name;
  std::string text;
};
// ReadGapInputs and DiagnoseGapReport on uploads: each is written into a fresh private folder,
// read by the same readers as a file and the folder removed. Every message names the upload,
// never the folder; the inputs' sources are the uploads' names. Throws what those throw.
GapReport DiagnoseGapUploads(const GapUpload& simulation, const std::vector<GapUpload>& measured,
                             const GapRunOptions& options);

io::Chart GapChart(const GapReport& report);

}  // namespace eol::station
