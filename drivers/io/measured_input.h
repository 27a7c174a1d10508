// What `eol analyze --measured FILE` reads: a frequency response or a raw recording, told apart
// by the extension and, for CSV (plain or .gz), by the header:
//   *.zma                              ZMA impedance (frf_files.h)
//   *.wav                              two-channel WAV recording, gains required
//   (recording_files.h) CSV with f_hz                      FRF CSV (frf_files.h) CSV with t_s
//   recording CSV (recording_files.h)
// Throws FileError for anything else, naming the file and what was expected.
#pragma once

#include <string>

#include "analysis/frf.h"
#include "analysis/signal/recording.h"

namespace eol::io {

enum class MeasuredKind { kFrf, kRecording };

struct MeasuredInput {
  MeasuredKind kind = MeasuredKind::kFrf;
  std::string format;             // "frf-csv", "zma", "recording-csv", "wav"
  analysis::Frf frf;              // kFrf
  analysis::Recording recording;  // kRecording (period_samples 0: the caller sets it)
};

// Gains of a WAV recording (V and A per unit of the converter's full scale); 0 = not given,
// an error for a WAV file.
struct WavGains {
  double voltage_gain_v = 0.0;
  double current_gain_a = 0.0;
};

MeasuredInput ReadMeasured(const std::string& path, const WavGains& gains);

}  // namespace eol::io
