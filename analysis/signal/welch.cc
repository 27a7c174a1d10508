#include "analysis/signal/welch.h"

#include <algorithm>
#include <cmath>
#include <complex>
#include <numbers>
#include <sstream>

#include "analysis/qc/statistics.h"
#include "analysis/signal/channel_checks.h"
#include "analysis/signal/fft.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;

std::vector<double> PeriodicHann(std::size_t m) {
  std::vector<double> w(m);
  for (std::size_t n = 0; n < m; ++n)
    w[n] = 0.5 -
           0.5 * std::cos(2.0 * std::numbers::pi * static_cast<double>(n) / static_cast<double>(m));
  return w;
}

// Welch's equivalent number of independent averages of K segments stepped by `step`.
double EquivalentAverages(const std::vector<double>& w, std::size_t step, std::size_t k) {
  double w2 = 0.0;
  for (double v : w) w2 += v * v;
  double sum = 0.0;
  for (std::size_t j = 1; j < k && j * step < w.size(); ++j) {
    double c = 0.0;
    for (std::size_t n = 0; n + j * step < w.size(); ++n) c += w[n] * w[n + j * step];
    const double rho = c / w2;
    sum += (1.0 - static_cast<double>(j) / static_cast<double>(k)) * rho * rho;
  }
  return static_cast<double>(k) / (1.0 + 2.0 * sum);
}

bool Constant(std::span<const double> x) {
  return std::all_of(x.begin(), x.end(), [&](double v) { return v == x.front(); });
}

}  // namespace

bool WelchOptions::IsValid(std::string* why) const {
  auto fail = [&](const std::string& m) {
    if (why) *why = m;
    return false;
  };
  if (segment_samples < 16) return fail("segment_samples must be at least 16");
  if (!(overlap >= 0.0 && overlap <= 0.95)) return fail("overlap must be in [0, 0.95]");
  if (!(f_lo_hz >= 0.0) || !(f_hi_hz >= 0.0))
    return fail("f_lo_hz and f_hi_hz must not be negative");
  if (f_hi_hz > 0.0 && !(f_hi_hz >= f_lo_hz)) return fail("f_hi_hz must not be below f_lo_hz");
  if (min_segments < 2)
    return fail("min_segments must be at least 2 (coherence of one segment is 1)");
  if (!(min_coherence >= 0.0 && min_coherence <= 1.0))
    return fail("min_coherence must be in [0, 1]");
  return true;
}

WelchSummary EstimateWelchFrf(const ChannelPair& pair, const WelchOptions& o) {
  WelchSummary out;
  std::string why;
  if (!o.IsValid(&why)) {
    out.message = "invalid options: " + why;
    return out;
  }
  if (!(pair.sample_rate_hz > 0.0)) {
    out.message = "sample rate must be positive";
    return out;
  }
  if (const ChannelProblem bad = CheckChannels(pair); !bad.empty()) {
    out.message = bad.message;
    out.clipped = bad.clipped;
    return out;
  }
  const std::size_t m = o.segment_samples;
  const std::size_t step =
      m - static_cast<std::size_t>(std::floor(o.overlap * static_cast<double>(m)));
  const std::size_t n = pair.x.size();
  const std::size_t k = n >= m ? (n - m) / step + 1 : 0;
  if (k < o.min_segments) {
    out.message = "record too short: " + std::to_string(n) + " samples give " + std::to_string(k) +
                  " segments of " + std::to_string(m) + "; need " + std::to_string(o.min_segments);
    return out;
  }
  for (auto [name, s] : {std::pair{&pair.x_name, pair.x}, {&pair.y_name, pair.y}}) {
    if (Constant(s)) {
      out.message = "no signal: the " + *name + " channel is constant";
      return out;
    }
  }

  const std::vector<double> w = PeriodicHann(m);
  const RealFft fft(m);
  const std::size_t bins = m / 2 + 1;
  std::vector<double> gxx(bins, 0.0), gyy(bins, 0.0);
  std::vector<Cplx> gxy(bins, 0.0);
  std::vector<double> xs(m), ys(m);
  for (std::size_t s = 0; s < k; ++s) {
    const std::size_t start = s * step;
    double mx = 0.0, my = 0.0;
    for (std::size_t i = 0; i < m; ++i) {
      mx += pair.x[start + i];
      my += pair.y[start + i];
    }
    mx /= static_cast<double>(m);
    my /= static_cast<double>(m);
    for (std::size_t i = 0; i < m; ++i) {
      xs[i] = (pair.x[start + i] - mx) * w[i];
      ys[i] = (pair.y[start + i] - my) * w[i];
    }
    const std::vector<Cplx> xf = fft.Forward(xs.data());
    const std::vector<Cplx> yf = fft.Forward(ys.data());
    for (std::size_t b = 0; b < bins; ++b) {
      gxx[b] += std::norm(xf[b]);
      gyy[b] += std::norm(yf[b]);
      gxy[b] += std::conj(xf[b]) * yf[b];
    }
  }
  out.segments = k;
  out.effective_averages = EquivalentAverages(w, step, k);

  const double df = pair.sample_rate_hz / static_cast<double>(m);
  const bool all = o.f_lo_hz == 0.0 && o.f_hi_hz == 0.0;
  Frf& h = out.frf;
  h.quantity = pair.quantity;
  h.method = o.estimator == WelchEstimator::kH1 ? "welch-h1" : "welch-h2";
  std::size_t empty_bins = 0;
  for (std::size_t b = 1; b + 1 < bins || (b + 1 == bins && m % 2 == 1); ++b) {
    const double f = static_cast<double>(b) * df;
    if (!all && (f < o.f_lo_hz - 1e-9 * df || f > o.f_hi_hz + 1e-9 * df)) continue;
    if (gxx[b] == 0.0 || gyy[b] == 0.0 || std::abs(gxy[b]) == 0.0) {
      ++empty_bins;
      continue;
    }
    const double g2 = std::min(1.0, std::norm(gxy[b]) / (gxx[b] * gyy[b]));
    const Cplx h0 =
        o.estimator == WelchEstimator::kH1 ? gxy[b] / gxx[b] : gyy[b] / std::conj(gxy[b]);
    const double w_rad = 2.0 * std::numbers::pi * f;
    const Cplx jw_n = std::pow(Cplx(0.0, w_rad), pair.output_jw_power);
    const double rel = std::sqrt(std::max(1.0 - g2, 1e-30) / (g2 * out.effective_averages));
    h.freq_hz.push_back(f);
    h.value.push_back(jw_n * h0);
    h.sigma.push_back(std::abs(jw_n * h0) * rel);
    out.coherence.push_back(g2);
  }
  if (h.size() == 0) {
    out.message = "no bin with signal in the requested band";
    return out;
  }
  const double median_g2 = Median(out.coherence);
  std::ostringstream msg;
  if (median_g2 < o.min_coherence) {
    msg << "coherence too low: median " << median_g2 << " over " << h.size() << " bins from "
        << h.freq_hz.front() << " to " << h.freq_hz.back() << " Hz (need " << o.min_coherence
        << "); the " << pair.x_name << " does not explain the " << pair.y_name
        << " (no excitation, open circuit, or noise dominates)";
    out.message = msg.str();
    out.frf = Frf{};
    out.coherence.clear();
    return out;
  }
  if (!h.Validate(&out.message)) {
    out.frf = Frf{};
    out.coherence.clear();
    return out;
  }
  msg << h.method << " from " << k << " segments of " << m << " samples (" << out.effective_averages
      << " equivalent averages), " << h.size() << " bins, median coherence " << median_g2;
  if (empty_bins) msg << ", " << empty_bins << " bins without signal left out";
  out.usable = true;
  out.message = msg.str();
  return out;
}

}  // namespace eol::analysis
