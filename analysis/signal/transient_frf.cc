#include "analysis/signal/transient_frf.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <sstream>
#include <utility>

#include "analysis/signal/channel_checks.h"
#include "analysis/signal/fft.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

// The local polynomial fit around one excited bin: the window's bins, the row vector that
// gives T_hat(m0) from the window's values, its leverage s, and the residual projector.
struct LocalFit {
  std::vector<std::size_t> bins;
  Eigen::RowVectorXd at_center;  // e_0^T (K^T K)^-1 K^T
  double leverage = 0.0;         // |at_center|^2 = e_0^T (K^T K)^-1 e_0
  Eigen::MatrixXd residual;      // I - K (K^T K)^-1 K^T
};

// The 2 w nearest bins to m0 that are not multiples of P, inside [1, last]: w on each side,
// the missing ones taken further out on the other side at DC or Nyquist.
std::vector<std::size_t> WindowBins(std::size_t m0, std::size_t periods, std::size_t w,
                                    std::size_t last) {
  std::vector<std::size_t> below, above;
  for (std::size_t m = m0; m > 1 && below.size() < 2 * w;)
    if (--m % periods != 0) below.push_back(m);
  for (std::size_t m = m0; m < last && above.size() < 2 * w;)
    if (++m % periods != 0) above.push_back(m);
  std::size_t nb = std::min(w, below.size()), na = std::min(w, above.size());
  nb = std::min(below.size(), nb + (w - na));
  na = std::min(above.size(), na + (w - nb));
  std::vector<std::size_t> bins(below.begin(), below.begin() + static_cast<std::ptrdiff_t>(nb));
  std::reverse(bins.begin(), bins.end());
  bins.insert(bins.end(), above.begin(), above.begin() + static_cast<std::ptrdiff_t>(na));
  return bins;
}

LocalFit MakeLocalFit(std::size_t m0, std::size_t periods, const TransientFrfOptions& o,
                      std::size_t last) {
  LocalFit f;
  f.bins = WindowBins(m0, periods, o.half_width, last);
  const auto rows = static_cast<Eigen::Index>(f.bins.size());
  const auto cols = static_cast<Eigen::Index>(o.degree + 1);
  double r_max = 0.0;
  for (std::size_t b : f.bins)
    r_max = std::max(r_max, std::abs(static_cast<double>(b) - static_cast<double>(m0)));
  Eigen::MatrixXd k(rows, cols);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double x =
        (static_cast<double>(f.bins[static_cast<std::size_t>(i)]) - static_cast<double>(m0)) /
        r_max;
    double p = 1.0;
    for (Eigen::Index j = 0; j < cols; ++j, p *= x) k(i, j) = p;
  }
  const Eigen::MatrixXd pinv = k.colPivHouseholderQr().solve(Eigen::MatrixXd::Identity(rows, rows));
  f.at_center = pinv.row(0);
  f.leverage = f.at_center.squaredNorm();
  f.residual = Eigen::MatrixXd::Identity(rows, rows) - k * pinv;
  return f;
}

// Effective complex degrees of freedom tr(A)^2 / tr(A^2) of the pooled variance estimate
// sum_j |e_j|^2 / (q_j c) over the fits j (each a quadratic form in the noise of its bins).
double PooledDof(const std::vector<const LocalFit*>& fits, std::size_t q) {
  std::vector<std::size_t> all;
  for (const LocalFit* f : fits) all.insert(all.end(), f->bins.begin(), f->bins.end());
  std::sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  const auto n = static_cast<Eigen::Index>(all.size());
  Eigen::MatrixXd a = Eigen::MatrixXd::Zero(n, n);
  const double scale = 1.0 / (static_cast<double>(q) * static_cast<double>(fits.size()));
  for (const LocalFit* f : fits) {
    std::vector<Eigen::Index> at(f->bins.size());
    for (std::size_t i = 0; i < at.size(); ++i)
      at[i] = std::lower_bound(all.begin(), all.end(), f->bins[i]) - all.begin();
    for (std::size_t i = 0; i < at.size(); ++i)
      for (std::size_t j = 0; j < at.size(); ++j)
        a(at[i], at[j]) +=
            scale * f->residual(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
  }
  const double tr = a.trace();
  const double tr2 = (a * a).trace();
  return tr2 > 0.0 ? tr * tr / tr2 : 0.0;
}

}  // namespace

bool TransientFrfOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (degree > 6) return fail("degree must be at most 6");
  if (half_width < 1 || half_width > 50) return fail("half_width must be in [1, 50]");
  if (2 * half_width <= degree + 1)
    return fail("2 half_width must exceed degree + 1 (the residual needs degrees of freedom)");
  if (!(min_line_snr >= 0.0)) return fail("min_line_snr must not be negative");
  return true;
}

FrfSummary EstimateTransientTransfer(const ChannelPair& pair, const std::vector<std::size_t>& lines,
                                     const TransientFrfOptions& o) {
  FrfSummary out;
  std::string why;
  if (!o.IsValid(&why)) {
    out.message = "invalid options: " + why;
    return out;
  }
  if (const ChannelProblem bad = CheckPeriodicPair(pair, lines); !bad.empty()) {
    out.message = bad.message;
    out.clipped = bad.clipped;
    return out;
  }
  const std::size_t n = pair.period_samples;
  const std::size_t periods = pair.x.size() / n;
  if (periods < 2) {
    out.message = "only " + std::to_string(periods) +
                  " whole periods recorded; the transient-aware estimate needs 2";
    return out;
  }
  const std::size_t total = periods * n;
  const std::size_t last = total / 2 - 1;  // highest bin below Nyquist
  const RealFft fft(total);
  const std::vector<Cplx> x_bins = fft.Forward(pair.x.data());
  const std::vector<Cplx> y_bins = fft.Forward(pair.y.data());
  const double scale = 2.0 / static_cast<double>(total);

  const std::size_t nl = lines.size();
  const std::size_t q = 2 * o.half_width - (o.degree + 1);
  std::vector<LocalFit> fits(nl);
  std::vector<Cplx> x_c(nl), y_c(nl), syx(nl, 0.0);
  std::vector<double> sx2(nl, 0.0), sy2(nl, 0.0);
  for (std::size_t l = 0; l < nl; ++l) {
    const std::size_t m0 = periods * lines[l];
    fits[l] = MakeLocalFit(m0, periods, o, last);
    const LocalFit& f = fits[l];
    const auto rows = static_cast<Eigen::Index>(f.bins.size());
    Eigen::VectorXcd xw(rows), yw(rows);
    for (Eigen::Index i = 0; i < rows; ++i) {
      xw[i] = x_bins[f.bins[static_cast<std::size_t>(i)]] * scale;
      yw[i] = y_bins[f.bins[static_cast<std::size_t>(i)]] * scale;
    }
    x_c[l] = x_bins[m0] * scale - (f.at_center.cast<Cplx>() * xw)(0);
    y_c[l] = y_bins[m0] * scale - (f.at_center.cast<Cplx>() * yw)(0);
    const Eigen::VectorXcd ex = f.residual.cast<Cplx>() * xw;
    const Eigen::VectorXcd ey = f.residual.cast<Cplx>() * yw;
    const double dq = static_cast<double>(q);
    sx2[l] = ex.squaredNorm() / dq;
    sy2[l] = ey.squaredNorm() / dq;
    syx[l] = ex.dot(ey) / dq;  // sum conj(ex) ey = e_Y . conj(e_X)
  }

  Frf& h = out.frf;
  h.quantity = pair.quantity;
  h.method = "transient-lpm";
  const double df = pair.sample_rate_hz / static_cast<double>(n);
  const std::size_t hw = o.noise_smoothing_lines;
  std::size_t weak_lines = 0;
  double worst_snr = std::numeric_limits<double>::infinity();
  for (std::size_t l = 0; l < nl; ++l) {
    const std::size_t lo = l >= hw ? l - hw : 0;
    const std::size_t hi = std::min(nl - 1, l + hw);
    double py2 = 0.0, px2 = 0.0;
    Cplx pyx = 0.0;
    for (std::size_t j = lo; j <= hi; ++j) {
      py2 += sy2[j];
      px2 += sx2[j];
      pyx += syx[j];
    }
    const double count = static_cast<double>(hi - lo + 1);
    const double inflate = 1.0 + fits[l].leverage;
    py2 *= inflate / count;
    px2 *= inflate / count;
    pyx *= inflate / count;
    const Cplx x = x_c[l];
    const double snr_x =
        px2 > 0.0 ? std::abs(x) / std::sqrt(px2) : std::numeric_limits<double>::infinity();
    worst_snr = std::min(worst_snr, snr_x);
    if (std::abs(x) == 0.0 || snr_x < o.min_line_snr) {
      ++weak_lines;
      continue;
    }
    const Cplx h0 = y_c[l] / x;
    double var = (py2 + std::norm(h0) * px2 - 2.0 * std::real(std::conj(h0) * pyx)) / std::norm(x);
    // A noise-free pair (simulation) has var ~ 0 (or slightly negative from rounding): keep
    // sigma positive, as Frf requires.
    var = std::max(var, 1e-30 * std::norm(h0) + std::numeric_limits<double>::min());
    const double f = static_cast<double>(lines[l]) * df;
    const Cplx jw_n = std::pow(Cplx(0.0, 2.0 * std::numbers::pi * f), pair.output_jw_power);
    h.freq_hz.push_back(f);
    h.value.push_back(jw_n * h0);
    h.sigma.push_back(std::abs(jw_n) * std::sqrt(var));
  }
  out.periods_used = periods;
  out.periods_dropped = 0;
  {
    const std::size_t mid = nl / 2;
    std::vector<const LocalFit*> pool;
    for (std::size_t j = mid >= hw ? mid - hw : 0; j <= std::min(nl - 1, mid + hw); ++j)
      pool.push_back(&fits[j]);
    out.noise_dof = PooledDof(pool, q);
  }
  if (std::string none = NoSignalMessage(pair, weak_lines, nl, worst_snr); !none.empty()) {
    out.message = std::move(none);
    return out;
  }
  std::ostringstream m;
  m << "transient-aware LPM estimate from " << periods << " periods (none dropped; degree "
    << o.degree << ", " << o.half_width << " bins each side), " << h.size() << " lines";
  if (weak_lines) m << ", " << weak_lines << " weak lines dropped";
  if (!h.Validate(&out.message)) return out;
  out.usable = true;
  out.message = m.str();
  return out;
}

FrfSummary EstimateTransientFrf(const Recording& recording, const std::vector<std::size_t>& lines,
                                const TransientFrfOptions& options) {
  return EstimateTransientTransfer(ChannelPair::Impedance(recording), lines, options);
}

}  // namespace eol::analysis
