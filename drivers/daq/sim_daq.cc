#include "drivers/daq/sim_daq.h"

#include <algorithm>
#include <chrono>
#include <random>
#include <thread>

#include "analysis/sim/steady_state.h"

namespace eol::drivers {

SimDaq::SimDaq(std::shared_ptr<SimBench> bench, SimDaqSettings settings)
    : Daq("sim"), bench_(std::move(bench)), settings_(settings) {}

analysis::Recording SimDaq::DoAcquire(const AcquisitionRequest& req,
                                      const std::atomic<bool>& abort) {
  const std::size_t total = req.excitation_v.size();
  const std::size_t period = req.period_samples > 0 ? req.period_samples : total;
  if (total % period != 0)
    throw DeviceError("excitation of " + std::to_string(total) +
                      " samples is not a whole number of periods of " + std::to_string(period));

  // The motor's steady-state current for one period (open circuit when no part).
  std::vector<double> current_period(period, 0.0);
  if (const auto part = bench_->part()) {
    const analysis::MotionalImpedance z = part->Electrical();
    const std::vector<double> u_period(req.excitation_v.begin(),
                                       req.excitation_v.begin() + static_cast<long>(period));
    current_period = analysis::SteadyStateCurrent([&](double f) { return z.At(f); }, u_period,
                                                  req.sample_rate_hz);
  }

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

  const auto chunk = std::max<std::size_t>(1, static_cast<std::size_t>(settings_.chunk_s * req.sample_rate_hz));
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t first = 0; first < total; first += chunk) {
    if (abort.load()) throw AcquisitionAborted();
    if (bench_->FaultActive(SimFault::kDaqFails))
      throw DeviceError("input overrun at sample " + std::to_string(first) +
                        " (simulated: daq_fails)");
    const bool connected = bench_->excitation_connected();
    const std::size_t last = std::min(total, first + chunk);
    for (std::size_t t = first; t < last; ++t) {
      const double u = connected ? req.excitation_v[t] : 0.0;
      const double i = connected ? current_period[t % period] : 0.0;
      rec.voltage_v[t] = std::clamp(u + vn(rng), -settings_.voltage_full_scale_v,
                                    settings_.voltage_full_scale_v);
      rec.current_a[t] = std::clamp(i + in(rng), -settings_.current_full_scale_a,
                                    settings_.current_full_scale_a);
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
