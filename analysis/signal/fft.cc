#include "analysis/signal/fft.h"

#include <fftw3.h>

#include <cstring>
#include <mutex>
#include <stdexcept>

namespace eol::analysis {
namespace {
// FFTW's planner is not thread-safe; execution of distinct plans is.
std::mutex& PlannerMutex() {
  static std::mutex m;
  return m;
}
}  // namespace

struct RealFft::Impl {
  std::size_t n;
  double* in = nullptr;
  fftw_complex* out = nullptr;
  fftw_plan forward = nullptr;
  fftw_plan inverse = nullptr;
  mutable std::mutex exec;  // the buffers are shared by both plans

  explicit Impl(std::size_t n_) : n(n_) {
    std::lock_guard<std::mutex> lock(PlannerMutex());
    in = fftw_alloc_real(n);
    out = fftw_alloc_complex(n / 2 + 1);
    if (!in || !out) throw std::bad_alloc();
    const int ni = static_cast<int>(n);
    forward = fftw_plan_dft_r2c_1d(ni, in, out, FFTW_ESTIMATE);
    inverse = fftw_plan_dft_c2r_1d(ni, out, in, FFTW_ESTIMATE);
    if (!forward || !inverse) throw std::runtime_error("FFTW could not make a plan");
  }
  ~Impl() {
    std::lock_guard<std::mutex> lock(PlannerMutex());
    if (forward) fftw_destroy_plan(forward);
    if (inverse) fftw_destroy_plan(inverse);
    fftw_free(in);
    fftw_free(out);
  }
};

RealFft::RealFft(std::size_t n) : n_(n) {
  if (n < 2) throw std::invalid_argument("RealFft: length must be at least 2");
  impl_ = std::make_unique<Impl>(n);
}
RealFft::~RealFft() = default;
RealFft::RealFft(RealFft&&) noexcept = default;
RealFft& RealFft::operator=(RealFft&&) noexcept = default;

std::vector<std::complex<double>> RealFft::Forward(const double* x) const {
  std::lock_guard<std::mutex> lock(impl_->exec);
  std::memcpy(impl_->in, x, n_ * sizeof(double));
  fftw_execute(impl_->forward);
  std::vector<std::complex<double>> result(n_ / 2 + 1);
  for (std::size_t k = 0; k < result.size(); ++k) result[k] = {impl_->out[k][0], impl_->out[k][1]};
  return result;
}

std::vector<double> RealFft::Inverse(const std::vector<std::complex<double>>& spectrum) const {
  if (spectrum.size() != n_ / 2 + 1)
    throw std::invalid_argument("RealFft::Inverse: spectrum must have n/2+1 bins");
  std::lock_guard<std::mutex> lock(impl_->exec);
  for (std::size_t k = 0; k < spectrum.size(); ++k) {
    impl_->out[k][0] = spectrum[k].real();
    impl_->out[k][1] = spectrum[k].imag();
  }
  fftw_execute(impl_->inverse);  // c2r destroys its input; we refill it every call
  std::vector<double> result(impl_->in, impl_->in + n_);
  const double scale = 1.0 / static_cast<double>(n_);
  for (double& v : result) v *= scale;
  return result;
}

}  // namespace eol::analysis
