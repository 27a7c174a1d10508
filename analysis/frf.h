// Frequency response value type shared by estimation, fitting, judging and storage.
#pragma once

#include <complex>
#include <string>
#include <vector>

namespace eol::analysis {

// What an Frf's values are. Units follow from the quantity.
enum class Quantity {
  kImpedanceOhm,  // Z = U / I, ohm
  kMobility,      // angular velocity per current, rad/s/A (the bench's j*w*Theta/I)
};

const char* ToString(Quantity q);

// A measured or modelled frequency response on a set of lines.
// Invariants (checked by Validate): all vectors have the same length (sigma may be empty),
// frequencies are finite, positive and strictly increasing, values and sigmas are finite,
// sigmas are positive.
struct Frf {
  std::vector<double> freq_hz;
  std::vector<std::complex<double>> value;
  // Standard deviation of each complex estimate: E|dZ|^2 = sigma^2 (so each of Re and Im
  // has variance sigma^2 / 2). Empty when unknown.
  std::vector<double> sigma;
  Quantity quantity = Quantity::kImpedanceOhm;
  std::string method;  // how it was obtained: "periodic-eiv", "file", "model", ...

  std::size_t size() const { return freq_hz.size(); }
  bool has_sigma() const { return !sigma.empty(); }
  // Returns false and explains in *why (naming the line) when an invariant is broken.
  bool Validate(std::string* why) const;
};

// Two independent estimates of one response on the same lines (the looks of a sequential
// test) as one, line by line weighted by inverse variance:
//   Z = (Z_a / s_a^2 + Z_b / s_b^2) / (1 / s_a^2 + 1 / s_b^2),   s^-2 = s_a^-2 + s_b^-2.
// Throws std::invalid_argument naming the cause when the lines, quantities or sigmas differ
// or are missing (an estimate without sigma cannot be weighed).
Frf CombineIndependent(const Frf& a, const Frf& b);

}  // namespace eol::analysis
