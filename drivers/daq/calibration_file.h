// The calibration record as JSON: stored with every test (TestRecord::calibration), written
// by `eol calibrate` and read back when the station config names it.
//
//   {"shunt_ohm": 0.1, "divider_ratio": 1.0, "channel_delay_s": 2.0e-5,
//    "method": "reference_resistor", "date": "2026-11-22T07:30:00Z", "reference_ohm": 1.0,
//    "estimate": {...}}
//
// shunt_ohm > 0, divider_ratio > 0 and |channel_delay_s| < 0.01 s are required; "method"
// defaults to "nominal". A measured calibration (method "reference_resistor") must carry its
// date and reference_ohm > 0. "estimate" (the fit behind it: gain, delay, sigmas, chi2) is
// kept in the file for people and ignored when reading. Unknown keys are errors.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "drivers/daq/daq.h"
#include "drivers/io/json_config.h"

namespace eol::drivers {

nlohmann::json CalibrationToJson(const Calibration& calibration);
// Throws io::ConfigError naming the JSON path of the offending field.
Calibration ParseCalibration(const io::JsonObject& object);
// Throws io::ConfigError naming the file (and the JSON path) when it cannot be read or is invalid.
Calibration ReadCalibrationFile(const std::string& path);

// The "daq" config's calibration: "calibration_file" (a file as above) or an inline
// "calibration" object, never both; neither gives the nominal calibration `fallback`.
Calibration DaqCalibration(const io::JsonObject& daq, const Calibration& fallback);

}  // namespace eol::drivers
