// FFTW plans as RAII objects. Plans are made under one process-wide planner lock with
// FFTW_ESTIMATE, never from wisdom, so results do not depend on a machine's history.
#pragma once

#include <complex>
#include <cstddef>
#include <memory>
#include <vector>

namespace eol::analysis {

// Real-to-complex forward transform of a fixed length n. Not copyable; movable.
// Forward(x) returns the n/2+1 bins X_k = sum_t x_t exp(-2 pi i k t / n) (unscaled).
class RealFft {
 public:
  explicit RealFft(std::size_t n);
  ~RealFft();
  RealFft(RealFft&&) noexcept;
  RealFft& operator=(RealFft&&) noexcept;
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  std::size_t size() const { return n_; }
  // x.size() must equal size(). Thread-safe for distinct RealFft objects.
  std::vector<std::complex<double>> Forward(const double* x) const;
  // Inverse of Forward, scaled by 1/n so that Inverse(Forward(x)) == x.
  // spectrum.size() must be n/2+1.
  std::vector<double> Inverse(const std::vector<std::complex<double>>& spectrum) const;

 private:
  struct Impl;
  std::size_t n_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace eol::analysis
