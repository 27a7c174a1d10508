#include "drivers/daq/replay_daq.h"

#include <algorithm>
#include <cmath>
#include <exception>
#include <filesystem>

#include "drivers/io/recording_files.h"

namespace eol::drivers {

ReplayDaq::ReplayDaq(ReplayDaqSettings settings) : Daq("replay"), settings_(std::move(settings)) {}

void ReplayDaq::DoConnect() {
  namespace fs = std::filesystem;
  files_ = settings_.files;
  if (!settings_.directory.empty()) {
    std::error_code ec;
    if (!fs::is_directory(settings_.directory, ec))
      throw DeviceError("directory " + settings_.directory + ": not a readable directory");
    files_.clear();
    for (const auto& entry : fs::directory_iterator(settings_.directory, ec)) {
      const std::string ext = entry.path().extension().string();
      if (entry.is_regular_file() && (ext == ".csv" || ext == ".wav"))
        files_.push_back(entry.path().string());
    }
    if (ec) throw DeviceError("directory " + settings_.directory + ": " + ec.message());
    std::sort(files_.begin(), files_.end());
    if (files_.empty())
      throw DeviceError("directory " + settings_.directory + ": no *.csv or *.wav recordings");
  }
  if (files_.empty()) throw DeviceError("no recording files configured");
  for (const std::string& f : files_) {
    std::error_code ec;
    if (!fs::is_regular_file(f, ec)) throw DeviceError("recording " + f + ": no such file");
  }
  next_ = 0;
}

analysis::Recording ReplayDaq::DoAcquire(const AcquisitionRequest& req,
                                         const std::atomic<bool>& abort) {
  if (abort.load()) throw AcquisitionAborted();
  if (!settings_.repeat && next_ >= files_.size())
    throw DeviceError("no more recordings: all " + std::to_string(files_.size()) +
                      " were replayed");
  const std::string& path = settings_.repeat ? files_.front() : files_[next_];
  analysis::Recording rec;
  try {
    rec = io::ReadRecordingFile(path, settings_.voltage_v_per_fs, settings_.current_a_per_fs);
  } catch (const std::exception& e) {
    throw DeviceError(std::string("recording ") + e.what());
  }
  if (!settings_.repeat) ++next_;
  if (!(std::abs(rec.sample_rate_hz - req.sample_rate_hz) <= 1e-6 * req.sample_rate_hz))
    throw DeviceError("recording " + path + ": sample rate " + std::to_string(rec.sample_rate_hz) +
                      " Hz, the excitation needs " + std::to_string(req.sample_rate_hz) + " Hz");
  if (rec.voltage_v.size() != req.excitation_v.size() ||
      rec.current_a.size() != req.excitation_v.size())
    throw DeviceError("recording " + path + ": " + std::to_string(rec.voltage_v.size()) +
                      " samples, the excitation has " + std::to_string(req.excitation_v.size()));
  rec.sample_rate_hz = req.sample_rate_hz;
  rec.period_samples = req.period_samples;
  // A CSV that does not state its range gets the configured one (a WAV's is its gains).
  if (rec.voltage_full_scale_v == 0.0) rec.voltage_full_scale_v = settings_.voltage_full_scale_v;
  if (rec.current_full_scale_a == 0.0) rec.current_full_scale_a = settings_.current_full_scale_a;
  return rec;
}

}  // namespace eol::drivers
