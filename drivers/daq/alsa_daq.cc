#include "drivers/daq/alsa_daq.h"

#include <alsa/asoundlib.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <thread>
#include <vector>

#include "analysis/signal/reference_calibration.h"

namespace eol::drivers {

namespace {

constexpr unsigned kChannels = 2;

snd_pcm_format_t AlsaFormat(AlsaSampleFormat f) {
  switch (f) {
    case AlsaSampleFormat::kS16:
      return SND_PCM_FORMAT_S16_LE;
    case AlsaSampleFormat::kS32:
      return SND_PCM_FORMAT_S32_LE;
    case AlsaSampleFormat::kFloat:
      return SND_PCM_FORMAT_FLOAT_LE;
  }
  return SND_PCM_FORMAT_UNKNOWN;
}

std::size_t BytesPerSample(AlsaSampleFormat f) { return f == AlsaSampleFormat::kS16 ? 2 : 4; }

// "<what> on <stream> '<device>': <alsa message>"
[[noreturn]] void Fail(const std::string& what, const std::string& stream,
                       const std::string& device, int err) {
  throw DeviceError(what + " on " + stream + " '" + device + "': " + snd_strerror(err));
}

// Interleaved frames of kChannels samples in the device's format, as fractions of full scale.
class FrameBuffer {
 public:
  FrameBuffer(AlsaSampleFormat format, std::size_t frames)
      : format_(format), bytes_(frames * kChannels * BytesPerSample(format)) {}
  void* data() { return bytes_.data(); }
  void Set(std::size_t frame, unsigned channel, double x) {
    const std::size_t i = frame * kChannels + channel;
    switch (format_) {
      case AlsaSampleFormat::kS16: {
        const auto v = static_cast<std::int16_t>(std::lround(std::clamp(x, -1.0, 1.0) * 32767.0));
        std::memcpy(&bytes_[i * 2], &v, 2);
        break;
      }
      case AlsaSampleFormat::kS32: {
        const auto v =
            static_cast<std::int32_t>(std::llround(std::clamp(x, -1.0, 1.0) * 2147483647.0));
        std::memcpy(&bytes_[i * 4], &v, 4);
        break;
      }
      case AlsaSampleFormat::kFloat: {
        const auto v = static_cast<float>(x);
        std::memcpy(&bytes_[i * 4], &v, 4);
        break;
      }
    }
  }
  double Get(std::size_t frame, unsigned channel) const {
    const std::size_t i = frame * kChannels + channel;
    switch (format_) {
      case AlsaSampleFormat::kS16: {
        std::int16_t v;
        std::memcpy(&v, &bytes_[i * 2], 2);
        return v / 32768.0;
      }
      case AlsaSampleFormat::kS32: {
        std::int32_t v;
        std::memcpy(&v, &bytes_[i * 4], 4);
        return v / 2147483648.0;
      }
      case AlsaSampleFormat::kFloat: {
        float v;
        std::memcpy(&v, &bytes_[i * 4], 4);
        return v;
      }
    }
    return 0.0;
  }

 private:
  AlsaSampleFormat format_;
  std::vector<unsigned char> bytes_;
};

struct StreamGeometry {
  snd_pcm_uframes_t period = 0;
  snd_pcm_uframes_t buffer = 0;
};

StreamGeometry Configure(snd_pcm_t* pcm, const std::string& stream, const std::string& device,
                         const AlsaDaqSettings& s, unsigned rate_hz) {
  snd_pcm_hw_params_t* hw = nullptr;
  snd_pcm_hw_params_alloca(&hw);
  int err = snd_pcm_hw_params_any(pcm, hw);
  if (err < 0) Fail("no configuration", stream, device, err);
  if ((err = snd_pcm_hw_params_set_rate_resample(pcm, hw, 0)) < 0)
    Fail("cannot disable resampling", stream, device, err);
  if ((err = snd_pcm_hw_params_set_access(pcm, hw, SND_PCM_ACCESS_RW_INTERLEAVED)) < 0)
    Fail("interleaved access not supported", stream, device, err);
  if ((err = snd_pcm_hw_params_set_format(pcm, hw, AlsaFormat(s.format))) < 0)
    Fail(std::string("format ") + ToString(s.format) + " not supported", stream, device, err);
  if ((err = snd_pcm_hw_params_set_channels(pcm, hw, kChannels)) < 0)
    Fail("2 channels not supported", stream, device, err);
  if ((err = snd_pcm_hw_params_set_rate(pcm, hw, rate_hz, 0)) < 0)
    Fail("sample rate " + std::to_string(rate_hz) + " Hz not supported", stream, device, err);
  snd_pcm_uframes_t period = s.period_frames;
  int dir = 0;
  if ((err = snd_pcm_hw_params_set_period_size_near(pcm, hw, &period, &dir)) < 0)
    Fail("period of " + std::to_string(s.period_frames) + " frames refused", stream, device, err);
  snd_pcm_uframes_t buffer = period * s.buffer_periods;
  if ((err = snd_pcm_hw_params_set_buffer_size_near(pcm, hw, &buffer)) < 0)
    Fail("buffer of " + std::to_string(period * s.buffer_periods) + " frames refused", stream,
         device, err);
  if ((err = snd_pcm_hw_params(pcm, hw)) < 0) Fail("hw_params", stream, device, err);
  StreamGeometry g;
  snd_pcm_hw_params_get_period_size(hw, &g.period, &dir);
  snd_pcm_hw_params_get_buffer_size(hw, &g.buffer);

  snd_pcm_sw_params_t* sw = nullptr;
  snd_pcm_sw_params_alloca(&sw);
  if ((err = snd_pcm_sw_params_current(pcm, sw)) < 0) Fail("sw_params", stream, device, err);
  // Started explicitly (linked); an xrun stops the stream (stop threshold = buffer).
  snd_pcm_sw_params_set_start_threshold(pcm, sw, g.buffer * 2);
  snd_pcm_sw_params_set_stop_threshold(pcm, sw, g.buffer);
  snd_pcm_sw_params_set_avail_min(pcm, sw, g.period);
  if ((err = snd_pcm_sw_params(pcm, sw)) < 0) Fail("sw_params", stream, device, err);
  return g;
}

// The xrun message: "<kind> (xrun) on <stream> '<device>' at frame F: N of T frames
// <transferred>".
[[noreturn]] void Xrun(const std::string& kind, const std::string& stream,
                       const std::string& device, std::size_t frame, std::size_t total,
                       const std::string& verb, int err) {
  throw DeviceError(kind + " (xrun) on " + stream + " '" + device + "' at frame " +
                    std::to_string(frame) + ": " + std::to_string(frame) + " of " +
                    std::to_string(total) + " frames " + verb + " (" + snd_strerror(err) +
                    "); the recording is discarded");
}

}  // namespace

AlsaDaq::AlsaDaq(AlsaDaqSettings settings) : Daq("alsa"), settings_(std::move(settings)) {}

AlsaDaq::~AlsaDaq() { Close(); }

void AlsaDaq::Close() {
  if (playback_) {
    snd_pcm_drop(playback_);
    snd_pcm_close(playback_);
    playback_ = nullptr;
  }
  if (capture_) {
    snd_pcm_drop(capture_);
    snd_pcm_close(capture_);
    capture_ = nullptr;
  }
}

void AlsaDaq::DoConnect() {
  Close();
  int err = snd_pcm_open(&playback_, settings_.playback_device.c_str(), SND_PCM_STREAM_PLAYBACK, 0);
  if (err < 0) {
    playback_ = nullptr;
    Fail("cannot open", "playback", settings_.playback_device, err);
  }
  err = snd_pcm_open(&capture_, settings_.capture_device.c_str(), SND_PCM_STREAM_CAPTURE, 0);
  if (err < 0) {
    capture_ = nullptr;
    Close();
    Fail("cannot open", "capture", settings_.capture_device, err);
  }
}

void AlsaDaq::DoDisconnect() { Close(); }

analysis::Recording AlsaDaq::DoAcquire(const AcquisitionRequest& req,
                                       const std::atomic<bool>& abort) {
  const std::string& pdev = settings_.playback_device;
  const std::string& cdev = settings_.capture_device;
  if (!playback_ || !capture_) throw DeviceError("not open");
  const double rate = std::round(req.sample_rate_hz);
  if (std::abs(rate - req.sample_rate_hz) > 1e-9 * rate)
    throw DeviceError("sample rate " + std::to_string(req.sample_rate_hz) +
                      " Hz is not a whole number of hertz");
  const std::size_t total = req.excitation_v.size();
  if (req.period_samples > 0 && total % req.period_samples != 0)
    throw DeviceError("excitation of " + std::to_string(total) +
                      " samples is not a whole number of periods of " +
                      std::to_string(req.period_samples));
  double peak_v = 0.0;
  for (double v : req.excitation_v) peak_v = std::max(peak_v, std::abs(v));
  if (peak_v > settings_.output_v_per_fs)
    throw DeviceError("excitation peak " + std::to_string(peak_v) +
                      " V exceeds the line output's full scale " +
                      std::to_string(settings_.output_v_per_fs) + " V (gains/output_v_per_fs)");

  snd_pcm_drop(playback_);
  snd_pcm_drop(capture_);
  snd_pcm_unlink(capture_);  // a former link; fails harmlessly when there is none
  const auto rate_hz = static_cast<unsigned>(rate);
  const StreamGeometry pg = Configure(playback_, "playback", pdev, settings_, rate_hz);
  const StreamGeometry cg = Configure(capture_, "capture", cdev, settings_, rate_hz);
  const bool linked = snd_pcm_link(capture_, playback_) == 0;
  if (!linked)
    spdlog::warn(
        "daq alsa: capture '{}' and playback '{}' cannot be linked; starting them "
        "one after the other",
        cdev, pdev);

  FrameBuffer out(settings_.format, pg.buffer);
  FrameBuffer in(settings_.format, cg.period);
  std::size_t played = 0;  // frames handed to playback, excitation then silence
  auto fill = [&](std::size_t frames) {
    for (std::size_t f = 0; f < frames; ++f) {
      const std::size_t t = played + f;
      const double x = t < total ? req.excitation_v[t] / settings_.output_v_per_fs : 0.0;
      out.Set(f, 0, x);
      out.Set(f, 1, x);
    }
    const snd_pcm_sframes_t w =
        snd_pcm_writei(playback_, out.data(), static_cast<snd_pcm_uframes_t>(frames));
    if (w == -EPIPE || w == -ESTRPIPE)
      Xrun(w == -EPIPE ? "underrun" : "suspend", "playback", pdev, played, total, "played",
           static_cast<int>(w));
    if (w < 0) Fail("write", "playback", pdev, static_cast<int>(w));
    played += static_cast<std::size_t>(w);
  };
  auto stop = [&] {
    snd_pcm_drop(playback_);  // silence first
    snd_pcm_drop(capture_);
    if (linked) snd_pcm_unlink(capture_);
  };

  analysis::Recording rec;
  rec.sample_rate_hz = req.sample_rate_hz;
  rec.period_samples = req.period_samples;
  const Calibration& cal = settings_.calibration;
  rec.voltage_full_scale_v = cal.divider_ratio * settings_.voltage_v_per_fs;
  rec.current_full_scale_a = settings_.current_v_per_fs / cal.shunt_ohm;
  rec.voltage_v.resize(total);
  rec.current_a.resize(total);

  std::size_t captured = 0;
  bool stalled = false;
  try {
    // Linked: prefill, then one start for both. Unlinked: capture runs first, so that nothing
    // played is missed (a plugin may start playing as soon as it has data).
    int err = 0;
    if (linked) {
      fill(pg.buffer);
      if ((err = snd_pcm_start(playback_)) < 0) Fail("start (linked)", "playback", pdev, err);
    } else {
      if ((err = snd_pcm_start(capture_)) < 0) Fail("start", "capture", cdev, err);
      fill(pg.buffer);
      if (snd_pcm_state(playback_) == SND_PCM_STATE_PREPARED &&
          (err = snd_pcm_start(playback_)) < 0)
        Fail("start", "playback", pdev, err);
    }
    while (captured < total) {
      if (abort.load()) throw AcquisitionAborted();
      if (!stalled && settings_.stall_after_frames > 0 &&
          captured >= settings_.stall_after_frames) {
        stalled = true;
        std::this_thread::sleep_for(std::chrono::duration<double>(settings_.stall_s));
      }
      const snd_pcm_sframes_t avail = snd_pcm_avail_update(capture_);
      if (avail == -EPIPE || avail == -ESTRPIPE)
        Xrun(avail == -EPIPE ? "overrun" : "suspend", "capture", cdev, captured, total, "recorded",
             static_cast<int>(avail));
      if (avail > static_cast<snd_pcm_sframes_t>(cg.buffer))
        Xrun("overrun", "capture", cdev, captured, total, "recorded", -EPIPE);
      const std::size_t want = std::min<std::size_t>(cg.period, total - captured);
      const snd_pcm_sframes_t r =
          snd_pcm_readi(capture_, in.data(), static_cast<snd_pcm_uframes_t>(want));
      if (r == -EPIPE || r == -ESTRPIPE)
        Xrun(r == -EPIPE ? "overrun" : "suspend", "capture", cdev, captured, total, "recorded",
             static_cast<int>(r));
      if (r == -EAGAIN) continue;
      if (r < 0) Fail("read", "capture", cdev, static_cast<int>(r));
      for (std::size_t f = 0; f < static_cast<std::size_t>(r); ++f) {
        rec.voltage_v[captured + f] = cal.divider_ratio * settings_.voltage_v_per_fs * in.Get(f, 0);
        rec.current_a[captured + f] = settings_.current_v_per_fs * in.Get(f, 1) / cal.shunt_ohm;
      }
      captured += static_cast<std::size_t>(r);

      const snd_pcm_sframes_t space = snd_pcm_avail_update(playback_);
      if (space == -EPIPE || space == -ESTRPIPE)
        Xrun(space == -EPIPE ? "underrun" : "suspend", "playback", pdev, played, total, "played",
             static_cast<int>(space));
      if (space < 0) Fail("avail", "playback", pdev, static_cast<int>(space));
      if (space > 0) fill(std::min<std::size_t>(static_cast<std::size_t>(space), pg.buffer));
    }
  } catch (...) {
    stop();
    throw;
  }
  stop();
  if (req.period_samples > 0 && cal.channel_delay_s != 0.0)
    analysis::DelayPeriodic(rec.current_a, -cal.channel_delay_s, req.sample_rate_hz);
  return rec;
}

}  // namespace eol::drivers
