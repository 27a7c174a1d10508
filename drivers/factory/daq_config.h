// The "daq" config of the alsa and replay drivers, and the calibration keys every driver
// shares (drivers/factory/factory.h lists the drivers). Each throws io::ConfigError naming the JSON
// path.
//
//   "daq": {"driver": "alsa", "playback": "default", "capture": "default",
//           "format": "S32_LE" | "S16_LE" | "FLOAT_LE", "period_frames": 1024,
//           "buffer_periods": 4,
//           "gains": {"output_v_per_fs": 1.0, "voltage_v_per_fs": 1.0, "current_v_per_fs": 1.0},
//           "calibration": {"shunt_ohm": 0.1, "divider_ratio": 1.0, "channel_delay_s": 0},
//           "stall_after_frames": 0, "stall_s": 0}          (alsa_daq.h; the stall is a test hook)
//   "daq": {"driver": "replay", "files": ["a.csv", "b.wav"] | "directory": "runs/" |
//           "file": "a.csv", "repeat": true,
//           "gains": {"voltage_v_per_fs": 1.0, "current_a_per_fs": 1.0},
//           "full_scale": {"voltage_v": 10, "current_a": 2}}   (replay_daq.h; optional: the
//           range of CSV recordings that do not state it, so samples at it count as clipped)
//   sim, added to its keys (sim_daq.h): "load": "fixture_part" | "reference_resistor",
//           "reference_ohm": 1.0, "injected_gain": 1.0, "injected_channel_delay_s": 0
//   any driver: "calibration": {...} inline, or "calibration_file": "calibration.json"
//           (calibration_file.h; the station resolves it against the config file's folder)
#pragma once

#include "drivers/daq/alsa_daq.h"
#include "drivers/daq/replay_daq.h"
#include "drivers/io/json_config.h"
#include "drivers/sim/sim_daq.h"

namespace eol::drivers {

AlsaDaqSettings ParseAlsaDaqSettings(const io::JsonObject& daq);
ReplayDaqSettings ParseReplayDaqSettings(const io::JsonObject& daq);
// The sim keys above and the calibration, into `settings`.
void ParseSimCalibrationLoad(const io::JsonObject& daq, SimDaqSettings& settings);

}  // namespace eol::drivers
