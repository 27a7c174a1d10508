// Time-domain simulator of the clamped motor on the bench (bench_circuit.h), integrated
// exactly from sample to sample, for any excitation stream and from any state (transients
// included).
//
// Continuous model, state x = [theta (n), omega (n), i] for a chain of n inertias
// (torsional_chain.h), input the amplifier voltage u_amp (V):
//   theta' = omega
//   M omega' = -K theta - C omega + b T i                 (torque T i on the magnets)
//   L i'     = u_amp - (R + R_out + R_sh) i - T b^T omega  (back-EMF T b^T omega)
// outputs y = [u_motor, i] with u_motor = u_amp - (R_out + R_sh) i, so that
// U / I = R + s L + T^2 Y_b(s) (torsional_chain.h) in the steady state.
// T is the transducer at the clamped rotor position, T = T_hat sin(p phi0) (pmsm_network.h):
// the rotor moves by microradians, so T(phi) is constant over a test.
//
// Discretisation (sample period Ts): between samples n and n+1 the input is a polynomial
// u(t_n + sigma Ts) = sum_j c_j sigma^j and the solution is exact,
//   x[n+1] = e^{A Ts} x[n] + sum_j Gamma_j c_j,
//   Gamma_j = int_0^1 e^{A Ts (1 - sigma)} B Ts sigma^j dsigma,
// with e^{A Ts} and every Gamma_j read off the matrix exponential of an augmented system
// (Eigen's unsupported MatrixFunctions, after diagonal balancing). The hold decides c_j:
//   kZeroOrder    u constant over the sample (c_0 = u[n]): what a DAC without reconstruction
//                 filter plays. The sampled staircase and the current it drives are then related
//                 by the ZOH equivalent, not by Z: U/I = Z e^{j w Ts/2} / sinc(f Ts) roughly, a
//                 half-sample skew (analysis/README.md 5) of several ohms in Re Z at 800 Hz and 8
//                 kHz.
//   kBandLimited  (default) u is the Lagrange polynomial through the hold_points samples
//                 n-h+1 .. n+h around the interval (h = hold_points/2), which approaches the
//                 band-limited interpolation of the samples (a DAC with its reconstruction
//                 filter): with 16 points its error is below 1e-8 up to 0.1 fs, so the streams
//                 agree with the frequency-domain steady state (steady_state.h) to ~1e-10 of
//                 their peak on the recipe's multisine (tests/analysis/time_domain_sim_test.cc).
//                 It reads h samples ahead: the stream is known in advance.
// Samples outside the stream are 0 (the amplifier is silent before and after).
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/model/torsional_chain.h"
#include "analysis/signal/recording.h"
#include "analysis/sim/bench_circuit.h"

namespace eol::analysis {

enum class InputHold { kZeroOrder, kBandLimited };

struct TimeDomainOptions {
  double sample_rate_hz = 8000.0;
  BenchCircuit circuit;
  InputHold hold = InputHold::kBandLimited;
  int hold_points = 16;  // kBandLimited: even, 2..32

  bool IsValid(std::string* why) const;
};

// The continuous model above: x' = A x + B u, y = C x + D u, y = [u_motor, i].
struct StateSpace {
  Eigen::MatrixXd a;
  Eigen::VectorXd b;
  Eigen::MatrixXd c;  // 2 x states
  Eigen::Vector2d d;
};
// Throws std::invalid_argument when the chain is invalid or R + R_out + R_sh or L is not
// positive.
StateSpace ClampedMotorStateSpace(const ClampedMotor& motor, const BenchCircuit& circuit);

// e^M computed as D e^{D^-1 M D} D^-1 with D a power-of-two diagonal balancing M's rows and
// columns, so that states of very different scales (rad, rad/s, A) keep their accuracy.
Eigen::MatrixXd BalancedExp(const Eigen::MatrixXd& m);

class TimeDomainSimulator {
 public:
  // Throws std::invalid_argument with the reason for invalid options or motor.
  TimeDomainSimulator(const ClampedMotor& motor, const TimeDomainOptions& options);

  void Reset();  // back to rest: every state 0
  // For each sample n in [first, last) of the amplifier stream u_amp: writes the outputs at
  // t_n (u_motor to voltage_v[n - first], i to current_a[n - first]), then steps to t_{n+1}.
  // Calls must continue where the previous one stopped (or after Reset, from any n).
  void Run(const std::vector<double>& u_amp, std::size_t first, std::size_t last, double* voltage_v,
           double* current_a);

  int states() const { return static_cast<int>(ad_.rows()); }

 private:
  double Input(const std::vector<double>& u, std::ptrdiff_t n) const;

  Eigen::MatrixXd ad_;      // e^{A Ts}
  Eigen::MatrixXd lambda_;  // states x taps: x[n+1] = ad x[n] + lambda [u[n+t_0] .. u[n+t_last]]
  int first_tap_ = 0;       // offset t_0 of the first tap (0 for ZOH, 1 - h otherwise)
  Eigen::MatrixXd c_;
  Eigen::Vector2d d_;
  Eigen::VectorXd x_;
  Eigen::VectorXd taps_;
};

struct ChannelNoise {
  double voltage_v = 0.0;  // rms per sample, white Gaussian
  double current_a = 0.0;
  std::uint64_t seed = 1;
};

// Adds the channel noise to a recording (one draw per sample and channel, voltage first).
void AddChannelNoise(const ChannelNoise& noise, Recording* recording);

// The whole stream from rest, with noise added to each channel (full scales left 0).
Recording SimulateRecording(const ClampedMotor& motor, const TimeDomainOptions& options,
                            const std::vector<double>& amplifier_v, std::size_t period_samples,
                            const ChannelNoise& noise);

}  // namespace eol::analysis
