#include "drivers/io/measured_input.h"

#include <algorithm>
#include <cctype>

#include "drivers/io/file_error.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/recording_files.h"
#include "drivers/io/text_table.h"

namespace eol::io {
namespace {

bool EndsWith(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  return std::equal(suffix.rbegin(), suffix.rend(), s.rbegin(), [](char a, char b) {
    return std::tolower(static_cast<unsigned char>(a)) ==
           std::tolower(static_cast<unsigned char>(b));
  });
}

bool Has(const std::vector<std::string>& names, const char* name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

MeasuredInput ReadMeasured(const std::string& path, const WavGains& gains) {
  MeasuredInput in;
  if (EndsWith(path, ".zma")) {
    in.format = "zma";
    in.frf = ReadZma(path);
    return in;
  }
  if (EndsWith(path, ".wav")) {
    if (!(gains.voltage_gain_v > 0.0) || !(gains.current_gain_a > 0.0))
      throw FileError(path, 0, 0,
                      "a WAV recording needs --voltage-gain and --current-gain (V and A per unit "
                      "of full scale)");
    in.kind = MeasuredKind::kRecording;
    in.format = "wav";
    in.recording = ReadWavRecording(path, gains.voltage_gain_v, gains.current_gain_a);
    return in;
  }
  const std::vector<std::string> header = ReadCsvHeader(path);
  if (Has(header, "f_hz")) {
    in.format = "frf-csv";
    in.frf = ReadFrfCsv(path);
    return in;
  }
  if (Has(header, "t_s")) {
    in.kind = MeasuredKind::kRecording;
    in.format = "recording-csv";
    in.recording = ReadRecordingCsv(path);
    return in;
  }
  throw FileError(path, 1, 0,
                  "unknown file: expected a .zma or .wav file, an FRF CSV (header f_hz,re_ohm,"
                  "im_ohm[,sigma_ohm]) or a recording CSV (header t_s,u_v,i_a)");
}

}  // namespace eol::io
