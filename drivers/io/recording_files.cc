#include "drivers/io/recording_files.h"

#include <sndfile.h>

#include <cctype>
#include <cmath>
#include <fstream>
#include <locale>
#include <memory>
#include <sstream>
#include <string_view>

#include "drivers/io/text_table.h"

namespace eol::io {
namespace {

struct SndfileCloser {
  void operator()(SNDFILE* f) const { sf_close(f); }
};
using SndfilePtr = std::unique_ptr<SNDFILE, SndfileCloser>;

// An optional full-scale column: one positive value repeated in every row; 0 when absent.
double StatedFullScale(const CsvTable& t, std::string_view name) {
  const std::size_t c = t.Find(name);
  if (c == std::string::npos) return 0.0;
  const std::vector<double>& v = t.columns[c];
  for (std::size_t k = 0; k < v.size(); ++k) {
    if (!(v[k] > 0.0)) throw t.ErrorAt(k, c, std::string(name) + " must be positive");
    if (v[k] != v.front())
      throw t.ErrorAt(k, c, std::string(name) + " must be the same in every row (the range)");
  }
  return v.front();
}

}  // namespace

analysis::Recording ReadRecordingCsv(const std::string& path) {
  const CsvTable t = ReadCsvTable(path);
  const auto& ts = t.Column("t_s");
  analysis::Recording rec;
  rec.voltage_v = t.Column("u_v");
  rec.current_a = t.Column("i_a");
  const std::size_t ct = t.Find("t_s");
  const std::size_t n = t.rows();
  if (n < 2)
    throw FileError(path, t.row_line.back(), 0, "need at least 2 samples to infer the sample rate");
  const double dt = (ts.back() - ts.front()) / static_cast<double>(n - 1);
  if (!(dt > 0.0)) throw t.ErrorAt(n - 1, ct, "time must increase");
  // Times near the ends of double's range give an infinite span (the grid check below then
  // passes anything, and the rate is 0) or a subnormal step (an infinite rate).
  if (!std::isfinite(dt) || !std::isfinite(1.0 / dt))
    throw t.ErrorAt(n - 1, ct,
                    "the sample interval " + (std::ostringstream() << dt).str() +
                        " s gives no finite sample rate");
  for (std::size_t k = 1; k < n; ++k) {
    const double expected = ts.front() + static_cast<double>(k) * dt;
    if (std::abs(ts[k] - expected) > 0.01 * dt)
      throw t.ErrorAt(k, ct,
                      "sampling is not uniform: expected t = " + std::to_string(expected) +
                          " s for a sample interval of " + std::to_string(dt) + " s");
  }
  double fs = 1.0 / dt;
  if (std::abs(fs - std::round(fs)) <= 1e-6 * fs) fs = std::round(fs);
  rec.sample_rate_hz = fs;
  rec.voltage_full_scale_v = StatedFullScale(t, "u_full_scale_v");
  rec.current_full_scale_a = StatedFullScale(t, "i_full_scale_a");
  return rec;
}

void WriteRecordingCsv(const std::string& path, const analysis::Recording& rec) {
  if (rec.voltage_v.size() != rec.current_a.size() || !(rec.sample_rate_hz > 0.0))
    throw FileError(path, 0, 0, "refusing to write a recording with unequal channels or no rate");
  std::ofstream out(path);
  if (!out) throw FileError(path, 0, 0, "cannot open for writing");
  out.imbue(std::locale::classic());
  out << "t_s,u_v,i_a\n";
  for (std::size_t k = 0; k < rec.voltage_v.size(); ++k) {
    out.precision(12);
    out << static_cast<double>(k) / rec.sample_rate_hz << ',';
    out.precision(17);
    out << rec.voltage_v[k] << ',' << rec.current_a[k] << '\n';
  }
  out.flush();
  if (!out) throw FileError(path, 0, 0, "write failed");
}

analysis::Recording ReadWavRecording(const std::string& path, double voltage_gain_v,
                                     double current_gain_a) {
  if (!(voltage_gain_v > 0.0) || !(current_gain_a > 0.0) || !std::isfinite(voltage_gain_v) ||
      !std::isfinite(current_gain_a))
    throw FileError(path, 0, 0, "the voltage and current gains must be positive");
  SF_INFO info{};
  SndfilePtr f(sf_open(path.c_str(), SFM_READ, &info));
  if (!f) throw FileError(path, 0, 0, std::string("cannot open as audio: ") + sf_strerror(nullptr));
  if (info.channels != 2)
    throw FileError(path, 0, 0,
                    "need 2 channels (voltage, current), found " + std::to_string(info.channels));
  if (info.frames <= 0) throw FileError(path, 0, 0, "no samples");
  std::vector<double> frames(static_cast<std::size_t>(info.frames) * 2);
  const sf_count_t got = sf_readf_double(f.get(), frames.data(), info.frames);
  if (got != info.frames)
    throw FileError(path, 0, 0,
                    "read " + std::to_string(got) + " of " + std::to_string(info.frames) +
                        " frames: " + sf_strerror(f.get()));
  analysis::Recording rec;
  rec.sample_rate_hz = static_cast<double>(info.samplerate);
  rec.voltage_v.resize(static_cast<std::size_t>(got));
  rec.current_a.resize(static_cast<std::size_t>(got));
  for (std::size_t k = 0; k < rec.voltage_v.size(); ++k) {
    rec.voltage_v[k] = frames[2 * k] * voltage_gain_v;
    rec.current_a[k] = frames[2 * k + 1] * current_gain_a;
    // Float encodings can hold NaN and infinities, and a 64-bit float near its maximum
    // overflows once scaled by the gain; the CSV reader refuses non-finite values too.
    for (int c = 0; c < 2; ++c)
      if (!std::isfinite(c == 0 ? rec.voltage_v[k] : rec.current_a[k]))
        throw FileError(path, 0, 0,
                        "frame " + std::to_string(k) + ": the " + (c == 0 ? "voltage" : "current") +
                            " sample is not a finite number once scaled by its gain");
  }
  rec.voltage_full_scale_v = voltage_gain_v;
  rec.current_full_scale_a = current_gain_a;
  return rec;
}

void WriteWavRecording(const std::string& path, const analysis::Recording& rec,
                       double voltage_gain_v, double current_gain_a) {
  const double fs = std::round(rec.sample_rate_hz);
  if (rec.voltage_v.size() != rec.current_a.size() || !(fs >= 1.0) ||
      std::abs(fs - rec.sample_rate_hz) > 1e-9 * fs)
    throw FileError(path, 0, 0, "refusing to write: unequal channels or a non-integer rate");
  if (!(voltage_gain_v > 0.0) || !(current_gain_a > 0.0))
    throw FileError(path, 0, 0, "the voltage and current gains must be positive");
  SF_INFO info{};
  info.samplerate = static_cast<int>(fs);
  info.channels = 2;
  info.format = SF_FORMAT_WAV | SF_FORMAT_FLOAT;
  SndfilePtr f(sf_open(path.c_str(), SFM_WRITE, &info));
  if (!f)
    throw FileError(path, 0, 0, std::string("cannot open for writing: ") + sf_strerror(nullptr));
  std::vector<double> frames(rec.voltage_v.size() * 2);
  for (std::size_t k = 0; k < rec.voltage_v.size(); ++k) {
    frames[2 * k] = rec.voltage_v[k] / voltage_gain_v;
    frames[2 * k + 1] = rec.current_a[k] / current_gain_a;
  }
  const auto n = static_cast<sf_count_t>(rec.voltage_v.size());
  if (sf_writef_double(f.get(), frames.data(), n) != n)
    throw FileError(path, 0, 0, std::string("write failed: ") + sf_strerror(f.get()));
}

analysis::Recording ReadRecordingFile(const std::string& path, double voltage_gain_v,
                                      double current_gain_a) {
  std::string ext = path.size() >= 4 ? path.substr(path.size() - 4) : "";
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".wav") return ReadWavRecording(path, voltage_gain_v, current_gain_a);
  return ReadRecordingCsv(path);
}

}  // namespace eol::io
