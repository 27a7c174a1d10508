#include "analysis/signal/periodic_frf.h"

#include <cmath>
#include <complex>
#include <sstream>

#include "analysis/signal/fft.h"

namespace eol::analysis {
namespace {

using Cplx = std::complex<double>;
using Spectra = std::vector<std::vector<Cplx>>;  // [period][line]

// Index of the first non-finite sample, or -1.
long FirstNonFinite(const std::vector<double>& x) {
  for (std::size_t i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i])) return static_cast<long>(i);
  return -1;
}

std::size_t CountClipped(const std::vector<double>& x, double full_scale) {
  if (full_scale <= 0.0) return 0;
  std::size_t n = 0;
  for (double v : x)
    if (std::abs(v) >= 0.999 * full_scale) ++n;
  return n;
}

Spectra LineSpectra(const std::vector<double>& x, std::size_t n, std::size_t periods,
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

FrfSummary EstimatePeriodicFrf(const Recording& rec, const std::vector<std::size_t>& lines,
                               const PeriodicFrfOptions& o) {
  FrfSummary out;
  std::string why;
  if (!o.IsValid(&why)) {
    out.message = "invalid options: " + why;
    return out;
  }
  const std::size_t n = rec.period_samples;
  if (n < 2 || lines.empty()) {
    out.message = "recording is not periodic or no lines are excited";
    return out;
  }
  if (rec.voltage_v.size() != rec.current_a.size()) {
    out.message = "voltage and current have different lengths (" +
                  std::to_string(rec.voltage_v.size()) + " vs " +
                  std::to_string(rec.current_a.size()) + " samples)";
    return out;
  }
  if (lines.back() >= n / 2) {
    out.message = "excited line " + std::to_string(lines.back()) + " is above Nyquist";
    return out;
  }
  for (auto [name, x] : {std::pair{"voltage", &rec.voltage_v}, {"current", &rec.current_a}}) {
    const long bad = FirstNonFinite(*x);
    if (bad >= 0) {
      out.message = std::string(name) + " sample " + std::to_string(bad) + " is not finite (NaN or inf)";
      return out;
    }
  }
  const std::size_t clipped_u = CountClipped(rec.voltage_v, rec.voltage_full_scale_v);
  const std::size_t clipped_i = CountClipped(rec.current_a, rec.current_full_scale_a);
  if (clipped_u + clipped_i > 0) {
    std::ostringstream m;
    m << "clipping: " << clipped_u << " voltage and " << clipped_i
      << " current samples at full scale; lower the excitation level or raise the range";
    out.message = m.str();
    return out;
  }
  const std::size_t periods = rec.voltage_v.size() / n;
  if (periods < o.transient_periods + o.min_periods) {
    out.message = "only " + std::to_string(periods) + " whole periods recorded; need " +
                  std::to_string(o.transient_periods + o.min_periods);
    return out;
  }

  const RealFft fft(n);
  const Spectra u_all = LineSpectra(rec.voltage_v, n, periods, lines, fft);
  const Spectra i_all = LineSpectra(rec.current_a, n, periods, lines, fft);
  std::size_t first = o.transient_periods;
  while (periods - first > o.min_periods &&
         LeadingPeriodDeviation(u_all, i_all, first) > o.transient_threshold)
    ++first;
  const std::size_t p_used = periods - first;
  const double pd = static_cast<double>(p_used);

  Frf& z = out.frf;
  z.quantity = Quantity::kImpedanceOhm;
  z.method = "periodic-eiv";
  std::size_t weak_lines = 0;
  double worst_snr = 1e300;
  for (std::size_t l = 0; l < lines.size(); ++l) {
    const Cplx u = MeanOf(u_all, first, l);
    const Cplx i = MeanOf(i_all, first, l);
    double su2 = 0.0, si2 = 0.0;
    Cplx sui = 0.0;
    for (std::size_t p = first; p < periods; ++p) {
      const Cplx du = u_all[p][l] - u;
      const Cplx di = i_all[p][l] - i;
      su2 += std::norm(du);
      si2 += std::norm(di);
      sui += du * std::conj(di);
    }
    su2 /= pd - 1.0;
    si2 /= pd - 1.0;
    sui /= pd - 1.0;
    const double snr_i = si2 > 0.0 ? std::abs(i) / std::sqrt(si2 / pd) : 1e300;
    worst_snr = std::min(worst_snr, snr_i);
    if (std::abs(i) == 0.0 || std::abs(u) == 0.0 || snr_i < o.min_line_snr) {
      ++weak_lines;
      continue;
    }
    const Cplx zk = u / i;
    double rel = su2 / std::norm(u) + si2 / std::norm(i) - 2.0 * std::real(sui / (u * std::conj(i)));
    // Guard against a noise-free channel pair (simulation): keep sigma positive.
    rel = std::max(rel, 1e-30);
    z.freq_hz.push_back(static_cast<double>(lines[l]) * rec.sample_rate_hz / static_cast<double>(n));
    z.value.push_back(zk);
    z.sigma.push_back(std::abs(zk) * std::sqrt(rel / pd));
  }
  out.periods_used = p_used;
  out.periods_dropped = first;
  // More than a tenth of the lines without current is no measurement (open circuit, relay
  // off, amplifier dead); a few weak lines are dropped and said.
  if (weak_lines * 10 > lines.size()) {
    std::ostringstream m;
    m << "no signal: " << weak_lines << " of " << lines.size()
      << " excited lines have no current above the noise (worst line SNR " << worst_snr
      << "); check the excitation relay, amplifier and wiring";
    out.message = m.str();
    return out;
  }
  std::ostringstream m;
  m << "periodic EIV estimate from " << p_used << " periods (" << first << " dropped), "
    << z.size() << " lines";
  if (weak_lines) m << ", " << weak_lines << " weak lines dropped";
  out.message = m.str();
  out.usable = z.Validate(&out.message) ? true : false;
  if (out.usable) out.message = m.str();
  return out;
}

}  // namespace eol::analysis
