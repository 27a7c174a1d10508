#include "drivers/factory/daq_config.h"

#include <cmath>

#include "drivers/daq/calibration_file.h"

namespace eol::drivers {

namespace {

std::size_t Count(const io::JsonObject& o, const std::string& key, std::size_t fallback,
                  std::size_t lo, std::size_t hi) {
  const int v = o.Integer(key, static_cast<int>(fallback));
  o.Require(v >= static_cast<int>(lo) && v <= static_cast<int>(hi), key,
            "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  return static_cast<std::size_t>(v);
}

double PositiveGain(const io::JsonObject& o, const std::string& key, double fallback) {
  const double v = o.Number(key, fallback);
  o.Require(v > 0.0 && std::isfinite(v), key, "must be positive (volts or amperes per full scale)");
  return v;
}

}  // namespace

AlsaDaqSettings ParseAlsaDaqSettings(const io::JsonObject& o) {
  AlsaDaqSettings s;
  s.playback_device = o.String("playback", s.playback_device);
  s.capture_device = o.String("capture", s.capture_device);
  const std::string format = o.String("format", ToString(s.format));
  if (format == ToString(AlsaSampleFormat::kS16)) {
    s.format = AlsaSampleFormat::kS16;
  } else if (format == ToString(AlsaSampleFormat::kS32)) {
    s.format = AlsaSampleFormat::kS32;
  } else if (format == ToString(AlsaSampleFormat::kFloat)) {
    s.format = AlsaSampleFormat::kFloat;
  } else {
    o.Require(false, "format", "must be \"S16_LE\", \"S32_LE\" or \"FLOAT_LE\"");
  }
  s.period_frames = Count(o, "period_frames", s.period_frames, 16, 65536);
  s.buffer_periods = Count(o, "buffer_periods", s.buffer_periods, 2, 64);
  if (auto g = o.OptionalObject("gains")) {
    s.output_v_per_fs = PositiveGain(*g, "output_v_per_fs", s.output_v_per_fs);
    s.voltage_v_per_fs = PositiveGain(*g, "voltage_v_per_fs", s.voltage_v_per_fs);
    s.current_v_per_fs = PositiveGain(*g, "current_v_per_fs", s.current_v_per_fs);
    g->RejectUnknown();
  }
  s.calibration = DaqCalibration(o, s.calibration);
  s.stall_after_frames = Count(o, "stall_after_frames", 0, 0, 1 << 30);
  s.stall_s = o.Number("stall_s", 0.0);
  o.Require(s.stall_s >= 0.0 && s.stall_s <= 10.0, "stall_s", "must be in [0, 10] s");
  o.RejectUnknown();
  return s;
}

ReplayDaqSettings ParseReplayDaqSettings(const io::JsonObject& o) {
  ReplayDaqSettings s;
  const int sources =
      (o.Has("files") ? 1 : 0) + (o.Has("directory") ? 1 : 0) + (o.Has("file") ? 1 : 0);
  if (sources != 1)
    throw io::ConfigError(o.path() + ": give exactly one of \"files\", \"directory\" or \"file\"");
  if (o.Has("files")) {
    const nlohmann::json& files = o.Raw("files");
    o.Require(files.is_array() && !files.empty(), "files", "must be a non-empty list of paths");
    for (const auto& f : files) {
      o.Require(f.is_string() && !f.get<std::string>().empty(), "files",
                "must be a list of paths (strings)");
      s.files.push_back(f.get<std::string>());
    }
  } else if (o.Has("directory")) {
    s.directory = o.RequiredString("directory");
  } else {
    s.files.push_back(o.RequiredString("file"));
  }
  s.repeat = o.Bool("repeat", false);
  o.Require(!s.repeat || o.Has("file"), "repeat", "repeats one \"file\" only");
  if (auto g = o.OptionalObject("gains")) {
    s.voltage_v_per_fs = PositiveGain(*g, "voltage_v_per_fs", s.voltage_v_per_fs);
    s.current_a_per_fs = PositiveGain(*g, "current_a_per_fs", s.current_a_per_fs);
    g->RejectUnknown();
  }
  if (auto f = o.OptionalObject("full_scale")) {
    s.voltage_full_scale_v = PositiveGain(*f, "voltage_v", 1.0);
    s.current_full_scale_a = PositiveGain(*f, "current_a", 1.0);
    f->Require(f->Has("voltage_v") && f->Has("current_a"), "voltage_v",
               "give both voltage_v and current_a (the converter's range of each channel)");
    f->RejectUnknown();
  }
  s.calibration = DaqCalibration(o, s.calibration);
  o.RejectUnknown();
  return s;
}

#if EOL_FACTORY_WITH_SIM
void ParseSimCalibrationLoad(const io::JsonObject& o, SimDaqSettings& s) {
  const std::string load = o.String("load", ToString(s.load));
  if (load == ToString(SimLoad::kFixturePart)) {
    s.load = SimLoad::kFixturePart;
  } else if (load == ToString(SimLoad::kReferenceResistor)) {
    s.load = SimLoad::kReferenceResistor;
  } else {
    o.Require(false, "load", "must be \"fixture_part\" or \"reference_resistor\"");
  }
  s.reference_ohm = o.Number("reference_ohm", s.reference_ohm);
  s.injected_gain = o.Number("injected_gain", s.injected_gain);
  s.injected_channel_delay_s = o.Number("injected_channel_delay_s", s.injected_channel_delay_s);
  o.Require(s.reference_ohm > 0.0 && std::isfinite(s.reference_ohm), "reference_ohm",
            "must be positive");
  o.Require(s.injected_gain > 0.0 && std::isfinite(s.injected_gain), "injected_gain",
            "must be positive");
  o.Require(std::abs(s.injected_channel_delay_s) < 0.01, "injected_channel_delay_s",
            "must be within +-10 ms");
  o.Require(s.injected_channel_delay_s == 0.0 || s.model == SimMotorModel::kSteadyState ||
                s.load == SimLoad::kReferenceResistor,
            "injected_channel_delay_s", "needs the steady_state model (or the reference load)");
  s.calibration = DaqCalibration(o, s.calibration);
}

#endif

}  // namespace eol::drivers
