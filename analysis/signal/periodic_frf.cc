#include "analysis/signal/periodic_frf.h"

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
using Spectra = std::vector<std::vector<Cplx>>;  // [period][line]

Spectra LineSpectra(std::span<const double> x, std::size_t n, std::size_t periods,
                    const std::vector<std::size_t>& lines, const RealFft& fft) {
  Spectra s(periods, std::vector<Cplx>(lines.size()));
  const double scale = 2.0 / static_cast<double>(n);
  for (std::size_t p = 0; p < periods; ++p) {
    const std::vector<Cplx> bins = fft.Forward(x.data() + p * n);
    for (std::size_t l = 0; l < lines.size(); ++l) s[p][l] = bins[lines[l]] * scale;
  }
  return s;
}

// Mean over periods [first, end) of one line.
Cplx MeanOf(const Spectra& s, std::size_t first, std::size_t line) {
  Cplx m = 0.0;
  for (std::size_t p = first; p < s.size(); ++p) m += s[p][line];
  return m / static_cast<double>(s.size() - first);
}

// How far period `first` deviates from the mean of the later ones, in units of the scatter
// of those later periods (about 1 for a steady state).
double LeadingPeriodDeviation(const Spectra& u, const Spectra& i, std::size_t first) {
  const std::size_t rest = u.size() - first - 1;
  if (rest < 2) return 0.0;
  double dev = 0.0, scatter = 0.0;
  for (std::size_t l = 0; l < u[0].size(); ++l) {
    for (const Spectra* s : {&u, &i}) {
      const Cplx m = MeanOf(*s, first + 1, l);
      double var = 0.0;
      for (std::size_t p = first + 1; p < s->size(); ++p) var += std::norm((*s)[p][l] - m);
      var /= static_cast<double>(rest - 1);
      dev += std::norm((*s)[first][l] - m);
      scatter += var;
    }
  }
  return scatter > 0.0 ? std::sqrt(dev / scatter) : (dev > 0.0 ? 1e9 : 0.0);
}

}  // namespace

bool PeriodicFrfOptions::IsValid(std::string* why) const {
  if (min_periods < 2) {
    if (why) *why = "min_periods must be at least 2 (a sigma needs two periods)";
    return false;
  }
  if (!(transient_threshold > 1.0)) {
    if (why) *why = "transient_threshold must be greater than 1";
    return false;
  }
  if (!(min_line_snr >= 0.0)) {
    if (why) *why = "min_line_snr must not be negative";
    return false;
  }
  return true;
}

FrfSummary EstimatePeriodicTransfer(const ChannelPair& pair, const std::vector<std::size_t>& lines,
                                    const PeriodicFrfOptions& o) {
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
  if (periods < o.transient_periods + o.min_periods) {
    out.message = "only " + std::to_string(periods) + " whole periods recorded; need " +
                  std::to_string(o.transient_periods + o.min_periods);
    return out;
  }

  const RealFft fft(n);
  const Spectra y_all = LineSpectra(pair.y, n, periods, lines, fft);
  const Spectra x_all = LineSpectra(pair.x, n, periods, lines, fft);
  std::size_t first = o.transient_periods;
  while (periods - first > o.min_periods &&
         LeadingPeriodDeviation(y_all, x_all, first) > o.transient_threshold)
    ++first;
  const std::size_t p_used = periods - first;
  const double pd = static_cast<double>(p_used);
  const double df = pair.sample_rate_hz / static_cast<double>(n);

  Frf& h = out.frf;
  h.quantity = pair.quantity;
  h.method = "periodic-eiv";
  // Per-line means and period-to-period (co)variances, then pooled over neighbouring lines.
  const std::size_t nl = lines.size();
  std::vector<Cplx> y_mean(nl), x_mean(nl), syx(nl, 0.0);
  std::vector<double> sy2(nl, 0.0), sx2(nl, 0.0);
  for (std::size_t l = 0; l < nl; ++l) {
    y_mean[l] = MeanOf(y_all, first, l);
    x_mean[l] = MeanOf(x_all, first, l);
    for (std::size_t p = first; p < periods; ++p) {
      const Cplx dy = y_all[p][l] - y_mean[l];
      const Cplx dx = x_all[p][l] - x_mean[l];
      sy2[l] += std::norm(dy) / (pd - 1.0);
      sx2[l] += std::norm(dx) / (pd - 1.0);
      syx[l] += dy * std::conj(dx) / (pd - 1.0);
    }
  }
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
    py2 /= count;
    px2 /= count;
    pyx /= count;
    const Cplx x = x_mean[l];
    const double snr_x =
        px2 > 0.0 ? std::abs(x) / std::sqrt(px2 / pd) : std::numeric_limits<double>::infinity();
    worst_snr = std::min(worst_snr, snr_x);
    if (std::abs(x) == 0.0 || snr_x < o.min_line_snr) {
      ++weak_lines;
      continue;
    }
    const Cplx h0 = y_mean[l] / x;
    double var =
        (py2 + std::norm(h0) * px2 - 2.0 * std::real(std::conj(h0) * pyx)) / (pd * std::norm(x));
    // A noise-free pair (simulation) has var ~ 0 (or slightly negative from rounding): keep
    // sigma positive, as Frf requires.
    var = std::max(var, 1e-30 * std::norm(h0) + std::numeric_limits<double>::min());
    const double f = static_cast<double>(lines[l]) * df;
    const double w = 2.0 * std::numbers::pi * f;
    const Cplx jw_n = std::pow(Cplx(0.0, w), pair.output_jw_power);
    h.freq_hz.push_back(f);
    h.value.push_back(jw_n * h0);
    h.sigma.push_back(std::abs(jw_n) * std::sqrt(var));
  }
  out.periods_used = p_used;
  out.periods_dropped = first;
  out.noise_dof = (pd - 1.0) * static_cast<double>(2 * hw + 1);
  // More than a tenth of the lines without input is no measurement (open circuit, relay
  // off, amplifier dead); a few weak lines are dropped and said.
  if (std::string none = NoSignalMessage(pair, weak_lines, lines.size(), worst_snr);
      !none.empty()) {
    out.message = std::move(none);
    return out;
  }
  std::ostringstream m;
  m << "periodic EIV estimate from " << p_used << " periods (" << first << " dropped), " << h.size()
    << " lines";
  if (weak_lines) m << ", " << weak_lines << " weak lines dropped";
  if (!h.Validate(&out.message)) return out;
  out.usable = true;
  out.message = m.str();
  return out;
}

FrfSummary EstimatePeriodicFrf(const Recording& recording, const std::vector<std::size_t>& lines,
                               const PeriodicFrfOptions& options) {
  return EstimatePeriodicTransfer(ChannelPair::Impedance(recording), lines, options);
}

}  // namespace eol::analysis
