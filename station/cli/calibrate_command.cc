// `eol calibrate --config station.json --reference-ohm R [--out calibration.json]`: measures
// the acquisition's channel calibration with a reference resistor R in the fixture instead of
// a motor (analysis/signal/reference_calibration.h). Plays the recipe's multisine through the
// configured fixture and DAQ (the excitation relay is closed only while the emergency-stop
// chain and the door are fine), estimates the gain and the current channel's delay with their
// sigmas, and writes the corrected calibration (drivers/daq/calibration_file.h) to --out, or
// to stdout. The station uses it when its config names it ("daq": {"calibration_file": ...}).
// stdout gets one summary line when --out is given. Exit 1 when the estimate is not usable
// (nothing is written), 2 on a station fault or bad input.
#include <atomic>
#include <fstream>
#include <iostream>
#include <optional>

#include "analysis/signal/multisine.h"
#include "analysis/signal/reference_calibration.h"
#include "db/clock.h"
#include "drivers/daq/calibration_file.h"
#include "drivers/factory/factory.h"
#include "drivers/io/recording_files.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/config.h"
#include "station/daemon/recipe.h"
#include "station/daemon/safety.h"

namespace eol::station::cli {
namespace {

struct CalibrateArgs {
  std::string config;
  double reference_ohm = 0.0;
  std::string out;
  bool json = false;
};

// Connects, closes the excitation relay while the interlocks hold, acquires, opens it again.
analysis::Recording AcquireReference(drivers::DriverSet& d, const drivers::AcquisitionRequest& req,
                                     const SafetyOptions& safety) {
  if (drivers::Status s = d.fixture->Connect(); !s.ok()) throw std::runtime_error(s.message());
  if (drivers::Status s = d.fixture->Activate(); !s.ok()) throw std::runtime_error(s.message());
  if (drivers::Status s = d.daq->Connect(); !s.ok()) throw std::runtime_error(s.message());
  const auto in = d.fixture->ReadInputs();
  if (!in.ok()) throw std::runtime_error(in.status().message());
  if (!in.value().estop_ok) throw std::runtime_error("emergency stop chain open: not exciting");
  if (!in.value().door_closed) throw std::runtime_error("door open: not exciting");
  // The controller keeps the relay closed only while station_alive changes (safety.h).
  AliveSignal alive(*d.fixture);
  std::optional<drivers::StatusOr<analysis::Recording>> acquired;
  {
    if (drivers::Status s = alive.Fresh(); !s.ok()) throw std::runtime_error(s.message());
    AlivePump pump(alive, safety.alive_period_ms);
    if (drivers::Status s = d.fixture->Write(drivers::FixtureOutput::kExcitationEnable, true);
        !s.ok()) {
      (void)d.fixture->Write(drivers::FixtureOutput::kExcitationEnable, false);
      throw std::runtime_error(s.message());
    }
    const std::atomic<bool> abort{false};
    acquired.emplace(d.daq->Acquire(req, abort));
    (void)d.fixture->Write(drivers::FixtureOutput::kExcitationEnable, false);
  }
  auto& result = *acquired;
  (void)d.fixture->Deactivate();
  if (!result.ok()) throw std::runtime_error("acquisition failed: " + result.status().message());
  return std::move(result.value());
}

int RunCalibrate(const CalibrateArgs& a) {
  const StationConfig config = LoadStationConfig(a.config);
  const Recipe recipe = LoadRecipe(config.recipe_path);
  drivers::DriverSet d = drivers::MakeDrivers(config.drivers);
  const analysis::Excitation excitation = analysis::DesignMultisine(recipe.excitation);
  drivers::AcquisitionRequest req;
  req.sample_rate_hz = excitation.sample_rate_hz;
  req.period_samples = excitation.period_samples;
  req.excitation_v = excitation.Repeat(recipe.transient_periods + recipe.periods);

  const drivers::Calibration used = d.daq->calibration();
  const analysis::Recording rec = AcquireReference(d, req, config.safety);
  d.daq->Disconnect();
  d.fixture->Disconnect();

  analysis::ReferenceCalibrationOptions options;
  options.reference_ohm = a.reference_ohm;
  options.frf = recipe.analysis.frf;
  const analysis::ReferenceCalibrationSummary s =
      analysis::EstimateReferenceCalibration(rec, excitation.lines, options);
  if (!s.usable) {
    std::cerr << "eol calibrate: not usable: " << s.message << "\n";
    return 1;
  }
  drivers::Calibration cal = used;
  cal.shunt_ohm = used.shunt_ohm / s.gain;
  cal.channel_delay_s = used.channel_delay_s + s.delay_s;
  cal.method = "reference_resistor";
  cal.date = db::UtcNowIso8601();
  cal.reference_ohm = a.reference_ohm;
  nlohmann::json j = drivers::CalibrationToJson(cal);
  j["estimate"] = {{"gain", s.gain},
                   {"gain_sigma", s.gain_sigma},
                   {"delay_s", s.delay_s},
                   {"delay_sigma_s", s.delay_sigma_s},
                   {"magnitude_chi2_per_dof", s.magnitude_chi2_per_dof},
                   {"phase_chi2_per_dof", s.phase_chi2_per_dof},
                   {"lines", s.lines},
                   {"daq", d.daq->name()},
                   {"calibration_used", drivers::CalibrationToJson(used)}};
  const std::string text = j.dump(2) + "\n";
  if (a.out.empty()) {
    std::cout << text;
    return 0;
  }
  std::ofstream f(a.out);
  f << text;
  f.flush();
  if (!f) throw std::runtime_error("cannot write " + a.out);
  if (a.json)
    std::cout << nlohmann::json{{"calibration", a.out},
                                {"message", s.message},
                                {"estimate", j["estimate"]}}
                     .dump()
              << std::endl;
  else
    std::cout << "calibration " << a.out << ": " << s.message << "\n";
  return 0;
}

}  // namespace

void AddCalibrateCommand(CLI::App& app) {
  auto args = std::make_shared<CalibrateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "calibrate", "Measure the DAQ's channel gain and delay with a reference resistor");
  cmd->add_option("--config", args->config, "Station config (its fixture, DAQ and recipe)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--reference-ohm", args->reference_ohm,
                  "The reference resistor in the fixture, ohm")
      ->required();
  cmd->add_option("--out", args->out, "Calibration JSON to write (default: stdout)");
  cmd->add_flag("--json", args->json,
                "With --out: print one JSON object {calibration, message, estimate} instead of "
                "the text line (without --out the calibration JSON is printed anyway)");
  cmd->callback([args] { RunGuarded("calibrate", [args] { return RunCalibrate(*args); }); });
}

}  // namespace eol::station::cli
