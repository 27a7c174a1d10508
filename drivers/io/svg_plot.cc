#include "drivers/io/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <locale>
#include <sstream>
#include <stdexcept>
#include <tuple>

#include "drivers/io/axis_ticks.h"
#include "drivers/io/file_error.h"

namespace eol::io {
namespace {

constexpr int kLeft = 80, kRight = 180, kTop = 40, kGap = 30, kBottom = 50;

struct Axis {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double px_lo = 0.0, px_hi = 1.0;  // pixel of lo and hi

  double Map(double v) const {
    const double a = log ? std::log10(lo) : lo, b = log ? std::log10(hi) : hi;
    const double t = ((log ? std::log10(v) : v) - a) / (b - a);
    return px_lo + t * (px_hi - px_lo);
  }
  bool Valid(double v) const { return std::isfinite(v) && (!log || v > 0.0); }
};

std::string Escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string Num(double v) {
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os.precision(6);
  os << v;
  return os.str();
}

// Data range of x (or y) over series, padded; log axes use positive values only.
std::pair<double, double> Range(const std::vector<const std::vector<double>*>& values, bool log) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto* v : values)
    for (double x : *v)
      if (std::isfinite(x) && (!log || x > 0.0)) {
        lo = std::min(lo, x);
        hi = std::max(hi, x);
      }
  if (!std::isfinite(lo)) return {log ? 0.1 : 0.0, 1.0};
  if (hi <= lo) {
    const double d = log ? 0.0 : std::max(std::abs(lo) * 0.1, 1e-12);
    return log ? std::make_pair(lo / 2.0, hi * 2.0) : std::make_pair(lo - d, hi + d);
  }
  return {lo, hi};
}

void Polyline(std::ostringstream& os, const SvgSeries& s, const Axis& x, const Axis& y) {
  std::string points;
  auto flush = [&]() {
    if (points.empty()) return;
    os << "<polyline fill=\"none\" stroke=\"" << Escape(s.color) << "\" stroke-width=\""
       << Num(s.width) << "\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\""
       << points << "\"/>\n";
    points.clear();
  };
  for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
    if (!x.Valid(s.x[i]) || !y.Valid(s.y[i])) {
      flush();
      continue;
    }
    const double px = x.Map(s.x[i]);
    const double py = std::clamp(y.Map(s.y[i]), y.px_hi - 5.0, y.px_lo + 5.0);
    if (s.markers) {
      os << "<circle cx=\"" << Num(px) << "\" cy=\"" << Num(py) << "\" r=\"1.6\" fill=\""
         << Escape(s.color) << "\"/>\n";
    } else {
      points += Num(px) + "," + Num(py) + " ";
    }
  }
  flush();
}

}  // namespace

std::string RenderSvg(const SvgFigure& f) {
  if (f.panels.empty()) throw std::invalid_argument("RenderSvg: a figure needs a panel");
  const int n = static_cast<int>(f.panels.size());
  const int height = kTop + n * f.panel_height_px + (n - 1) * kGap + kBottom;
  std::ostringstream os;
  os.imbue(std::locale::classic());
  os << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
     << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << f.width_px << "\" height=\""
     << height << "\" viewBox=\"0 0 " << f.width_px << " " << height
     << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
     << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n"
     << "<text x=\"" << f.width_px / 2 << "\" y=\"22\" text-anchor=\"middle\" font-size=\"15\">"
     << Escape(f.title) << "</text>\n";

  std::vector<const std::vector<double>*> xs;
  for (const SvgPanel& p : f.panels)
    for (const SvgSeries& s : p.series) xs.push_back(&s.x);
  Axis x;
  x.log = f.log_x;
  std::tie(x.lo, x.hi) = Range(xs, f.log_x);
  x.px_lo = kLeft;
  x.px_hi = f.width_px - kRight;
  const std::vector<double> xticks = f.log_x ? LogTicks(x.lo, x.hi) : LinearTicks(x.lo, x.hi);

  for (int i = 0; i < n; ++i) {
    const SvgPanel& p = f.panels[static_cast<std::size_t>(i)];
    const double top = kTop + i * (f.panel_height_px + kGap);
    const double bottom = top + f.panel_height_px;
    std::vector<const std::vector<double>*> ys;
    for (const SvgSeries& s : p.series) ys.push_back(&s.y);
    std::vector<double> h = p.hlines;
    ys.push_back(&h);
    Axis y;
    y.log = p.log_y;
    std::tie(y.lo, y.hi) = Range(ys, p.log_y);
    if (!p.log_y) {
      const double pad = 0.05 * (y.hi - y.lo);
      y.lo -= pad;
      y.hi += pad;
    }
    y.px_lo = bottom;
    y.px_hi = top;
    os << "<g>\n";
    for (const auto& [a, b] : p.shaded) {
      const double pa = std::clamp(x.Map(std::max(a, x.lo)), x.px_lo, x.px_hi);
      const double pb = std::clamp(x.Map(std::min(b, x.hi)), x.px_lo, x.px_hi);
      os << "<rect x=\"" << Num(pa) << "\" y=\"" << Num(top) << "\" width=\""
         << Num(std::max(pb - pa, 1.5)) << "\" height=\"" << f.panel_height_px
         << "\" fill=\"#f4a261\" fill-opacity=\"0.25\"/>\n";
    }
    const std::vector<double> yticks = p.log_y ? LogTicks(y.lo, y.hi) : LinearTicks(y.lo, y.hi);
    for (double t : yticks) {
      const double py = y.Map(t);
      os << "<line x1=\"" << kLeft << "\" x2=\"" << Num(x.px_hi) << "\" y1=\"" << Num(py)
         << "\" y2=\"" << Num(py) << "\" stroke=\"#ddd\"/>\n"
         << "<text x=\"" << kLeft - 6 << "\" y=\"" << Num(py + 4) << "\" text-anchor=\"end\">"
         << Num(t) << "</text>\n";
    }
    for (double t : xticks) {
      const double px = x.Map(t);
      os << "<line x1=\"" << Num(px) << "\" x2=\"" << Num(px) << "\" y1=\"" << Num(top)
         << "\" y2=\"" << Num(bottom) << "\" stroke=\"#eee\"/>\n";
      if (i == n - 1)
        os << "<text x=\"" << Num(px) << "\" y=\"" << Num(bottom + 16)
           << "\" text-anchor=\"middle\">" << Num(t) << "</text>\n";
    }
    for (double hl : p.hlines)
      if (y.Valid(hl))
        os << "<line x1=\"" << kLeft << "\" x2=\"" << Num(x.px_hi) << "\" y1=\"" << Num(y.Map(hl))
           << "\" y2=\"" << Num(y.Map(hl)) << "\" stroke=\"#555\" stroke-dasharray=\"2,3\"/>\n";
    for (const SvgSeries& s : p.series) Polyline(os, s, x, y);
    os << "<rect x=\"" << kLeft << "\" y=\"" << Num(top) << "\" width=\"" << Num(x.px_hi - kLeft)
       << "\" height=\"" << f.panel_height_px << "\" fill=\"none\" stroke=\"#333\"/>\n"
       << "<text transform=\"translate(18," << Num((top + bottom) / 2)
       << ") rotate(-90)\" text-anchor=\"middle\">" << Escape(p.y_label) << "</text>\n";
    double ly = top + 14;
    for (const SvgSeries& s : p.series) {
      if (s.label.empty()) continue;
      const double lx = x.px_hi + 12;
      if (s.markers)
        os << "<circle cx=\"" << Num(lx + 11) << "\" cy=\"" << Num(ly - 4) << "\" r=\"2.5\" fill=\""
           << Escape(s.color) << "\"/>\n";
      else
        os << "<line x1=\"" << Num(lx) << "\" x2=\"" << Num(lx + 22) << "\" y1=\"" << Num(ly - 4)
           << "\" y2=\"" << Num(ly - 4) << "\" stroke=\"" << Escape(s.color) << "\" stroke-width=\""
           << Num(std::max(s.width, 2.0)) << "\"" << (s.dashed ? " stroke-dasharray=\"6,4\"" : "")
           << "/>\n";
      os << "<text x=\"" << Num(lx + 28) << "\" y=\"" << Num(ly) << "\">" << Escape(s.label)
         << "</text>\n";
      ly += 16;
    }
    os << "</g>\n";
  }
  os << "<text x=\"" << Num((kLeft + x.px_hi) / 2) << "\" y=\"" << height - 12
     << "\" text-anchor=\"middle\">" << Escape(f.x_label) << "</text>\n</svg>\n";
  return os.str();
}

void WriteSvg(const std::string& path, const SvgFigure& figure) {
  const std::string svg = RenderSvg(figure);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw FileError(path, 0, 0, "cannot open for writing");
  out << svg;
  out.flush();
  if (!out) throw FileError(path, 0, 0, "write failed");
}

}  // namespace eol::io
