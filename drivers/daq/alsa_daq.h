// The acquisition driver for a sound interface (ALSA): line out 0 (and 1, the same signal)
// drives the power amplifier, line in 0 reads the phase-pair voltage through the divider and
// line in 1 the voltage across the current shunt. Playback and capture run at the request's
// rate, linked (snd_pcm_link) so that they start together; the two capture channels are one
// stream, so voltage and current are sample-synchronous whatever the link does. A device that
// cannot be linked (a plugin such as "pulse") is started capture first, then playback, and
// a warning says so.
//
// Units, from channel full scale (a sample of 1.0) to physical:
//   amplifier input  x = excitation_v / output_v_per_fs         (|x| <= 1, else refused)
//   voltage          u = divider_ratio * voltage_v_per_fs * ch0
//   current          i = current_v_per_fs * ch1 / shunt_ohm
// and the Recording's full scales are those of a sample of 1.0. With a periodic request the
// current channel is advanced by the calibration's channel_delay_s (a periodic fractional
// delay over the whole recording, analysis::DelayPeriodic), so U / I is skew-free.
//
// Xruns are never recovered into a result: an overrun (capture) or underrun (playback),
// EPIPE, or a suspend, ESTRPIPE, or a capture buffer found over-full (frames lost), stops
// both streams and throws DeviceError naming the device, the stream, the frame index and how
// many frames had been transferred. Abort drops the playback first (silence), then the
// capture. Config: drivers/factory/factory.h ("daq": {"driver": "alsa", ...}).
#pragma once

#include <cstddef>
#include <string>

#include "drivers/daq/daq.h"

typedef struct _snd_pcm snd_pcm_t;  // NOLINT: the C library's own name

namespace eol::drivers {

enum class AlsaSampleFormat { kS16, kS32, kFloat };
// "S16_LE", "S32_LE", "FLOAT_LE". Inline: the config reader (eol::driver_factory) and the
// driver (eol::drivers, only with ALSA) both need it, and the driver's target must not
// depend on the factory's.
inline const char* ToString(AlsaSampleFormat f) {
  switch (f) {
    case AlsaSampleFormat::kS16:
      return "S16_LE";
    case AlsaSampleFormat::kS32:
      return "S32_LE";
    case AlsaSampleFormat::kFloat:
      return "FLOAT_LE";
  }
  return "?";
}

struct AlsaDaqSettings {
  std::string playback_device = "default";
  std::string capture_device = "default";
  AlsaSampleFormat format = AlsaSampleFormat::kS32;
  std::size_t period_frames = 1024;  // transfer unit; latency and xrun margin follow from it
  std::size_t buffer_periods = 4;
  // Gains, in volts per full scale (a sample of 1.0).
  double output_v_per_fs = 1.0;   // line out: volts at the amplifier input
  double voltage_v_per_fs = 1.0;  // line in 0: volts at the input, before divider_ratio
  double current_v_per_fs = 1.0;  // line in 1: volts across the shunt
  Calibration calibration;
  // Test hook: the reader sleeps stall_s once after stall_after_frames captured frames (an
  // induced overrun). 0 = never.
  std::size_t stall_after_frames = 0;
  double stall_s = 0.0;
};

class AlsaDaq final : public Daq {
 public:
  explicit AlsaDaq(AlsaDaqSettings settings);
  ~AlsaDaq() override;

 protected:
  void DoConnect() override;
  void DoDisconnect() override;
  analysis::Recording DoAcquire(const AcquisitionRequest& request,
                                const std::atomic<bool>& abort) override;
  Calibration DoCalibration() const override { return settings_.calibration; }

 private:
  void Close();
  AlsaDaqSettings settings_;
  snd_pcm_t* playback_ = nullptr;
  snd_pcm_t* capture_ = nullptr;
};

}  // namespace eol::drivers
