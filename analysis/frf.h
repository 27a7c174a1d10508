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

}  // namespace eol::analysis
