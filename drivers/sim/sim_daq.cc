#include "drivers/sim/sim_daq.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <complex>
#include <optional>
#include <random>
#include <thread>

#include "analysis/signal/reference_calibration.h"
#include "analysis/sim/bench_circuit.h"
#include "analysis/sim/time_domain.h"

namespace eol::drivers {

const char* ToString(SimMotorModel m) {
  switch (m) {
    case SimMotorModel::kSteadyState:
      return "steady_state";
    case SimMotorModel::kTimeDomain:
      return "time_domain";
  }
  return "?";
}

const char* ToString(SimLoad l) {
  switch (l) {
    case SimLoad::kFixturePart:
      return "fixture_part";
    case SimLoad::kReferenceResistor:
      return "reference_resistor";
  }
  return "?";
}

SimDaq::SimDaq(std::shared_ptr<SimBench> bench, SimDaqSettings settings)
    : Daq("sim"), bench_(std::move(bench)), settings_(settings) {}

analysis::Recording SimDaq::DoAcquire(const AcquisitionRequest& req,
                                      const std::atomic<bool>& abort) {
  const std::size_t total = req.excitation_v.size();
  const std::size_t period = req.period_samples > 0 ? req.period_samples : total;
  if (total % period != 0)
    throw DeviceError("excitation of " + std::to_string(total) +
                      " samples is not a whole number of periods of " + std::to_string(period));

  // The motor in the bench circuit (open circuit when no part): one steady-state period, or
  // the time-domain simulator run chunk by chunk below.
  const bool reference = settings_.load == SimLoad::kReferenceResistor;
  const std::optional<analysis::SimUnit> part = reference ? std::nullopt : bench_->part();
  const analysis::BenchCircuit circuit{settings_.amplifier_output_ohm,
                                       settings_.calibration.shunt_ohm};
  analysis::ChannelSamples steady;
  std::unique_ptr<analysis::TimeDomainSimulator> sim;
  if (reference) {
    const double r_ohm = settings_.reference_ohm;
    const std::vector<double> u_period(req.excitation_v.begin(),
                                       req.excitation_v.begin() + static_cast<long>(period));
    steady = analysis::SteadyStatePeriod([r_ohm](double) { return std::complex<double>(r_ohm); },
                                         circuit, u_period, req.sample_rate_hz);
  } else if (part && settings_.model == SimMotorModel::kSteadyState) {
    const analysis::MotionalImpedance z = part->Electrical();
    const std::vector<double> u_period(req.excitation_v.begin(),
                                       req.excitation_v.begin() + static_cast<long>(period));
    steady = analysis::SteadyStatePeriod([&](double f) { return z.At(f); }, circuit, u_period,
                                         req.sample_rate_hz);
  } else if (part) {
    const analysis::ClampedMotor motor{part->r_ohm, part->l_h, part->rotor.transmission_nm_per_a,
                                       analysis::SingleModeChain(part->rotor)};
    analysis::TimeDomainOptions options;
    options.sample_rate_hz = req.sample_rate_hz;
    options.circuit = circuit;
    sim = std::make_unique<analysis::TimeDomainSimulator>(motor, options);
  }
  analysis::DelayPeriodic(steady.current_a, settings_.injected_channel_delay_s, req.sample_rate_hz);
  std::vector<double> u_motor, i_motor;

  std::mt19937_64 rng(settings_.seed + 1000003ULL * ++acquisitions_);
  std::normal_distribution<double> vn(0.0, settings_.voltage_noise_v);
  std::normal_distribution<double> in(0.0, settings_.current_noise_a);
  analysis::Recording rec;
  rec.sample_rate_hz = req.sample_rate_hz;
  rec.period_samples = req.period_samples;
  rec.voltage_full_scale_v = settings_.voltage_full_scale_v;
  rec.current_full_scale_a = settings_.current_full_scale_a;
  rec.voltage_v.resize(total);
  rec.current_a.resize(total);

  const auto chunk =
      std::max<std::size_t>(1, static_cast<std::size_t>(settings_.chunk_s * req.sample_rate_hz));
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t first = 0; first < total; first += chunk) {
    if (abort.load()) throw AcquisitionAborted();
    if (bench_->FaultActive(SimFault::kDaqFails))
      throw DeviceError("input overrun at sample " + std::to_string(first) +
                        " (simulated: daq_fails)");
    const bool connected = settings_.relay_external || bench_->excitation_connected();
    const std::size_t last = std::min(total, first + chunk);
    u_motor.assign(last - first, 0.0);
    i_motor.assign(last - first, 0.0);
    if (connected && !part && !reference) {  // open circuit: the amplifier's voltage, no current
      std::copy(req.excitation_v.begin() + static_cast<long>(first),
                req.excitation_v.begin() + static_cast<long>(last), u_motor.begin());
    } else if (connected && sim) {
      sim->Run(req.excitation_v, first, last, u_motor.data(), i_motor.data());
    } else if (connected) {
      for (std::size_t t = first; t < last; ++t) {
        u_motor[t - first] = steady.voltage_v[t % period];
        i_motor[t - first] = steady.current_a[t % period];
      }
    } else if (sim) {
      sim->Reset();  // relay open: the motor rests until it closes again
    }
    for (std::size_t t = first; t < last; ++t) {
      const double u = settings_.injected_gain * u_motor[t - first];
      const double i = i_motor[t - first];
      rec.voltage_v[t] =
          std::clamp(u + vn(rng), -settings_.voltage_full_scale_v, settings_.voltage_full_scale_v);
      rec.current_a[t] =
          std::clamp(i + in(rng), -settings_.current_full_scale_a, settings_.current_full_scale_a);
    }
    if (settings_.time_scale > 0.0) {
      const double played_s = static_cast<double>(last) / req.sample_rate_hz;
      std::this_thread::sleep_until(
          start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                      std::chrono::duration<double>(played_s * settings_.time_scale)));
    }
  }
  if (abort.load()) throw AcquisitionAborted();
  return rec;
}

}  // namespace eol::drivers
