// The acquisition driver for re-analysis: plays nothing and returns recordings read from
// files, one per acquisition, in order: a list of files, the files of a directory (sorted by
// name, *.csv and *.wav), or one file repeated for every acquisition. Past the last file of a
// list or directory an acquisition fails ("no more recordings").
//
// Each recording must fit the request: the same sample rate (within 1e-6 relative) and the
// same number of samples as the excitation; the request's period_samples is set on it (the
// files do not know the excitation). Errors name the file. Files are read by the one I/O
// library's readers (CSV t_s,u_v,i_a and two-channel WAV, drivers/io/recording_files.h).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "drivers/daq/daq.h"

namespace eol::drivers {

// voltage_v_per_fs and current_a_per_fs scale WAV files (full scale to volts / amperes).
struct ReplayDaqSettings {
  std::vector<std::string> files;  // in order; with repeat, exactly one
  std::string directory;           // instead of files
  bool repeat = false;             // the one file for every acquisition
  double voltage_v_per_fs = 1.0;   // WAV gains
  double current_a_per_fs = 1.0;
  // The converter's range of CSV recordings that do not state it (recording_files.h);
  // 0: unknown, clipping is then found from samples repeated at a rail (clipping.h).
  double voltage_full_scale_v = 0.0;
  double current_full_scale_a = 0.0;
  Calibration calibration;  // what the recordings were measured with
};

class ReplayDaq final : public Daq {
 public:
  explicit ReplayDaq(ReplayDaqSettings settings);

  // The files in the order they will be returned (directory listed at Connect).
  const std::vector<std::string>& files() const { return files_; }

 protected:
  void DoConnect() override;
  void DoDisconnect() override {}
  analysis::Recording DoAcquire(const AcquisitionRequest& request,
                                const std::atomic<bool>& abort) override;
  Calibration DoCalibration() const override { return settings_.calibration; }

 private:
  ReplayDaqSettings settings_;
  std::vector<std::string> files_;
  std::size_t next_ = 0;
};

}  // namespace eol::drivers
