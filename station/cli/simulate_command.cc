// `eol simulate`: test data from a simulated motor, so that anyone can make it. The motor is
// a JSON file (drivers/io/motor_json.h: winding, transducer, rotor chain, fixture), the
// excitation the recipe's multisine (transient and averaged periods), the bench the
// amplifier, shunt and noisy channels of analysis/sim/. Output:
//   --format frf        FRF CSV f_hz,re_ohm,im_ohm,sigma_ohm (drivers/io/frf_files.h): the
//                       periodic errors-in-variables estimate of the simulated recording, as
//                       the station would measure it (sigma = std of the complex estimate).
//                       With both noise levels 0: the exact model Z on the lines, no sigma.
//   --format recording  raw recording CSV t_s,u_v,i_a (recording_files.h), every period.
// stdout gets one line: the motor, its defect and the modes the chain shows in the band.
#include <cstdio>
#include <iostream>
#include <nlohmann/json.hpp>
#include <optional>

#include "analysis/model/rotor_chain.h"
#include "analysis/signal/multisine.h"
#include "analysis/signal/periodic_frf.h"
#include "analysis/sim/bench_circuit.h"
#include "analysis/sim/time_domain.h"
#include "drivers/io/frf_files.h"
#include "drivers/io/json_config.h"
#include "drivers/io/motor_json.h"
#include "drivers/io/recording_files.h"
#include "station/cli/commands.h"
#include "station/cli/common.h"
#include "station/daemon/data_files.h"
#include "station/daemon/recipe.h"

namespace eol::station::cli {
namespace {

struct SimulateArgs {
  std::string motor;
  std::string out;
  std::string defect;  // empty: the soft magnets of the motor file
  std::uint64_t seed = 1;
  std::optional<double> rotor_position_deg;
  std::string format = "frf";
  std::string model = "time_domain";
  std::string recipe = DefaultRecipePath();
  double noise_v = 2e-3;
  double noise_a = 1e-3;
  double amplifier_output_ohm = 0.0;
  double shunt_ohm = 0.1;
  bool json = false;
};

// The modes the torque excites inside [lo, hi], as "390.0 Hz (Q 54, Rp 0.571 ohm)".
std::string VisibleModes(const analysis::ClampedMotor& motor, double lo, double hi) {
  std::vector<analysis::MotionalImpedance> terms = motor.ModalTerms();
  double top = 0.0;
  for (const auto& t : terms) top = std::max(top, t.rp_ohm);
  std::string out;
  for (const auto& t : terms) {
    if (t.f0_hz < lo || t.f0_hz > hi || !(t.rp_ohm > 1e-3 * top)) continue;
    char buf[96];
    std::snprintf(buf, sizeof buf, "%s%.1f Hz (Q %.0f, Rp %.3g ohm)", out.empty() ? "" : ", ",
                  t.f0_hz, t.q, t.rp_ohm);
    out += buf;
  }
  return out.empty() ? "none" : out;
}

int RunSimulate(const SimulateArgs& a) {
  io::MotorSpec spec = io::LoadMotorJson(a.motor);
  if (!a.defect.empty()) {
    std::string why;
    if (!analysis::SoftMagnetsForDefect(a.defect, spec.rotor.magnets, &spec.rotor.soft_magnets,
                                        &why))
      throw io::ConfigError("--defect: " + why);
  }
  if (!spec.effects.empty())
    std::cerr << "eol simulate: motor " << spec.id << " lists " << spec.effects.size()
              << " effects; this command simulates the chain only, without them\n";
  const analysis::ClampedMotor motor = spec.Motor(a.rotor_position_deg);
  const Recipe recipe = LoadRecipe(a.recipe);
  const analysis::Excitation ex = analysis::DesignMultisine(recipe.excitation);
  const std::size_t periods = recipe.transient_periods + recipe.periods;
  const std::vector<double> u_amp = ex.Repeat(periods);

  const analysis::BenchCircuit circuit{a.amplifier_output_ohm, a.shunt_ohm};
  const analysis::ChannelNoise noise{a.noise_v, a.noise_a, a.seed};
  analysis::Recording rec;
  if (a.model == "time_domain") {
    analysis::TimeDomainOptions options;
    options.sample_rate_hz = ex.sample_rate_hz;
    options.circuit = circuit;
    rec = analysis::SimulateRecording(motor, options, u_amp, ex.period_samples, noise);
  } else {
    const analysis::ChannelSamples period = analysis::SteadyStatePeriod(
        [&](double f) { return motor.Impedance(f); }, circuit, ex.period_v, ex.sample_rate_hz);
    rec.sample_rate_hz = ex.sample_rate_hz;
    rec.period_samples = ex.period_samples;
    for (std::size_t p = 0; p < periods; ++p) {
      rec.voltage_v.insert(rec.voltage_v.end(), period.voltage_v.begin(), period.voltage_v.end());
      rec.current_a.insert(rec.current_a.end(), period.current_a.begin(), period.current_a.end());
    }
    analysis::AddChannelNoise(noise, &rec);
  }

  std::string wrote;
  if (a.format == "recording") {
    io::WriteRecordingCsv(a.out, rec);
    wrote = "recording of " + std::to_string(rec.voltage_v.size()) + " samples";
  } else if (a.noise_v == 0.0 && a.noise_a == 0.0) {
    io::WriteFrfCsv(a.out, motor.Evaluate(ex.LineFrequenciesHz()));
    wrote = "exact FRF (no noise, no sigma) of " + std::to_string(ex.lines.size()) + " lines";
  } else {
    const analysis::FrfSummary frf =
        analysis::EstimatePeriodicFrf(rec, ex.lines, recipe.analysis.frf);
    if (!frf.usable)
      throw std::runtime_error("the simulated recording gives no FRF: " + frf.message);
    io::WriteFrfCsv(a.out, frf.frf, 2.0 * frf.noise_dof);  // sigma^2's degrees of freedom
    wrote = "FRF of " + std::to_string(frf.frf.size()) + " lines";
  }
  if (a.json) {
    std::cout << nlohmann::json{{"motor", spec.id},
                                {"defect", a.defect.empty() ? "from the file" : a.defect},
                                {"soft_magnets", spec.rotor.soft_magnets.size()},
                                {"transmission_nm_per_a", motor.transmission_nm_per_a},
                                {"modes_in_band", VisibleModes(motor, recipe.excitation.f_lo_hz,
                                                               recipe.excitation.f_hi_hz)},
                                {"wrote", wrote},
                                {"out", a.out}}
                     .dump()
              << std::endl;
    return 0;
  }
  std::cout << "motor " << spec.id << ", defect "
            << (a.defect.empty() ? std::string("from the file") : a.defect) << " ("
            << spec.rotor.soft_magnets.size()
            << " soft magnets), T = " << motor.transmission_nm_per_a
            << " N m/A, modes in the band: "
            << VisibleModes(motor, recipe.excitation.f_lo_hz, recipe.excitation.f_hi_hz)
            << "; wrote " << wrote << " to " << a.out << "\n";
  return 0;
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Write test data of a simulated clamped motor: the motor file's winding, transducer,\n"
      "rotor chain (magnets, bonds, poles, bridges, shaft) and fixture, excited by the\n"
      "recipe's multisine through the bench (amplifier, shunt, noise on both channels).\n"
      "Writes an FRF CSV (f_hz,re_ohm,im_ohm,sigma_ohm) or a raw recording CSV (t_s,u_v,i_a).");
  cmd->add_option("--motor", args->motor,
                  "Motor JSON (format: drivers/io/motor_json.h; "
                  "examples in recipes/motors/)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out", args->out, "Output file")->required();
  cmd->add_flag("--json", args->json, "Print what was written as one JSON object on stdout");
  cmd->add_option("--defect", args->defect,
                  "Poorly cemented magnets: none, one_soft_magnet, all_soft or partial:<ratio> "
                  "(that share of the magnets); default: the motor file's soft_magnets");
  cmd->add_option("--seed", args->seed, "Seed of the channel noise")->capture_default_str();
  cmd->add_option("--rotor-position-deg", args->rotor_position_deg,
                  "Rotor position phi: T = T_hat sin(p phi) (needs t_hat_nm_per_a and poles in "
                  "the motor file); default: the file's");
  cmd->add_option("--format", args->format, "frf or recording")
      ->capture_default_str()
      ->check(CLI::IsMember({"frf", "recording"}));
  cmd->add_option("--model", args->model,
                  "time_domain (exact integration from rest, transient included) or "
                  "steady_state (frequency domain)")
      ->capture_default_str()
      ->check(CLI::IsMember({"time_domain", "steady_state"}));
  cmd->add_option("--recipe", args->recipe, "Recipe whose excitation is played")
      ->capture_default_str();
  cmd->add_option("--noise-v", args->noise_v, "Voltage channel noise, V rms per sample")
      ->capture_default_str()
      ->check(NonNegative());
  cmd->add_option("--noise-a", args->noise_a, "Current channel noise, A rms per sample")
      ->capture_default_str()
      ->check(NonNegative());
  cmd->add_option("--amplifier-output-ohm", args->amplifier_output_ohm,
                  "Amplifier output resistance in series with the motor")
      ->capture_default_str()
      ->check(NonNegative());
  cmd->add_option("--shunt-ohm", args->shunt_ohm, "Current shunt in series with the motor")
      ->capture_default_str()
      ->check(NonNegative());
  cmd->callback([args] { RunGuarded("simulate", [&] { return RunSimulate(*args); }); });
}

}  // namespace eol::station::cli
