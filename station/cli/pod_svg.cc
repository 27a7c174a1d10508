#include "station/cli/pod_svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "drivers/io/svg_plot.h"

namespace eol::station::cli {
namespace {

constexpr const char* kColours[] = {"#1f77b4", "#d62728", "#2ca02c",
                                    "#9467bd", "#ff7f0e", "#8c564b"};

io::SvgSeries Series(const std::string& label, const std::string& colour,
                     std::vector<double> x = {}, std::vector<double> y = {}) {
  io::SvgSeries s;
  s.label = label;
  s.color = colour;
  s.x = std::move(x);
  s.y = std::move(y);
  return s;
}

std::string Fixed(double v, int digits = 3) {
  if (!std::isfinite(v)) return "none";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

io::SvgFigure PodFigure(const std::string& title, const std::vector<PodCurve>& curves) {
  io::SvgFigure f;
  f.title = title;
  f.x_label = "defect size a (bond stiffness loss)";
  io::SvgPanel p;
  p.y_label = "POD";
  p.hlines = {0.9};
  double lo = 1.0, hi = 0.0;
  for (const PodCurve& c : curves)
    for (const auto& h : c.data) lo = std::min(lo, h.size), hi = std::max(hi, h.size);
  if (!(hi > lo)) lo = 0.01, hi = 1.0;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const PodCurve& c = curves[k];
    const std::string colour = kColours[k % 6];
    io::SvgSeries hits = Series(c.label + " hit/miss", colour);
    hits.markers = true;
    for (const auto& h : c.data) {
      hits.x.push_back(h.size);
      hits.y.push_back(h.hit ? 1.0 : 0.0);
    }
    p.series.push_back(hits);
    if (!c.fit.usable) continue;
    io::SvgSeries pod = Series(c.label + " POD", colour);
    io::SvgSeries bound = Series(c.label + " lower bound", colour);
    bound.dashed = true;
    bound.width = 1.0;
    for (int i = 0; i <= 200; ++i) {
      const double a = lo + (hi - lo) * i / 200.0;
      pod.x.push_back(a);
      pod.y.push_back(c.fit.Pod(a));
      bound.x.push_back(a);
      bound.y.push_back(c.fit.PodLowerWald(a));
    }
    p.series.push_back(pod);
    p.series.push_back(bound);
    if (std::isfinite(c.fit.a90_95_lr) && c.fit.a90_95_lr <= hi) {
      io::SvgSeries mark = Series(c.label + " a90/95 " + Fixed(c.fit.a90_95_lr), colour,
                                  {c.fit.a90_95_lr, c.fit.a90_95_lr}, {0.0, 1.0});
      mark.width = 2.5;
      p.series.push_back(mark);
    }
  }
  f.panels.push_back(p);
  return f;
}

io::SvgFigure F0Figure(const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits) {
  io::SvgFigure f;
  f.title = "fitted f0 per class against the taught limits";
  f.x_label = "f0 (Hz)";
  io::SvgPanel p;
  p.y_label = "share per 1 Hz";
  double lo = 1e300, hi = -1e300;
  for (const F0Group& g : groups)
    for (double v : g.f0_hz) lo = std::min(lo, v), hi = std::max(hi, v);
  for (const F0Limit& l : limits) lo = std::min(lo, l.f0_hz), hi = std::max(hi, l.f0_hz);
  lo = std::floor(lo);
  hi = std::ceil(hi) + 1.0;
  double top = 0.0;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const F0Group& g = groups[k];
    if (g.f0_hz.empty()) continue;
    std::vector<double> share(static_cast<std::size_t>(hi - lo), 0.0);
    for (double v : g.f0_hz) share[static_cast<std::size_t>(v - lo)] += 1.0 / g.f0_hz.size();
    io::SvgSeries s =
        Series(g.label + " (" + std::to_string(g.f0_hz.size()) + ")", kColours[k % 6]);
    for (std::size_t b = 0; b < share.size(); ++b) {  // a step line per bin
      s.x.insert(s.x.end(), {lo + b, lo + b + 1.0});
      s.y.insert(s.y.end(), {share[b], share[b]});
      top = std::max(top, share[b]);
    }
    p.series.push_back(s);
  }
  for (const F0Limit& l : limits) {
    io::SvgSeries s = Series(l.label + " " + Fixed(l.f0_hz, 2) + " Hz", "#000000",
                             {l.f0_hz, l.f0_hz}, {0.0, top});
    s.width = 2.5;
    p.series.push_back(s);
  }
  f.panels.push_back(p);
  return f;
}

// The document without its XML declaration, and its height from the root element.
std::string Inner(const std::string& doc, double* height) {
  const std::size_t start = doc.find("<svg");
  const std::size_t h = doc.find("height=\"", start);
  *height = std::stod(doc.substr(h + 8));
  return doc.substr(start);
}

}  // namespace

std::string PodSvg(const std::string& title, const std::vector<PodCurve>& curves,
                   const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits) {
  double h1 = 0.0, h2 = 0.0;
  const io::SvgFigure pod_figure = PodFigure(title, curves);
  std::string body = Inner(io::RenderSvg(pod_figure), &h1);
  bool any_f0 = false;
  for (const F0Group& g : groups) any_f0 = any_f0 || !g.f0_hz.empty();
  if (any_f0) {
    std::string second = Inner(io::RenderSvg(F0Figure(groups, limits)), &h2);
    second.insert(4, " y=\"" + std::to_string(static_cast<int>(h1)) + "\"");
    body += second;
  }
  return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" +
         std::to_string(pod_figure.width_px) + "\" height=\"" +
         std::to_string(static_cast<int>(h1 + h2)) + "\">\n" + body + "</svg>\n";
}

void WritePodSvg(const std::string& path, const std::string& title,
                 const std::vector<PodCurve>& curves, const std::vector<F0Group>& groups,
                 const std::vector<F0Limit>& limits) {
  std::ofstream out(path);
  if (out) out << PodSvg(title, curves, groups, limits);
  if (!out) throw std::runtime_error("cannot write the POD figure to '" + path + "'");
}

}  // namespace eol::station::cli
