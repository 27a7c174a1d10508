#include "station/cli/pod_svg.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <stdexcept>
#include <utility>

#include "drivers/io/chart.h"
#include "drivers/io/file_error.h"

namespace eol::station::cli {
namespace {

constexpr io::Colour kColours[] = {io::kChartBlue,   io::kChartRed,    io::kChartGreen,
                                   io::kChartPurple, io::kChartOrange, {0.549, 0.337, 0.294}};

io::ChartSeries Series(const std::string& label, const io::Colour& colour,
                       std::vector<double> x = {}, std::vector<double> y = {}) {
  io::ChartSeries s;
  s.label = label;
  s.colour = colour;
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

io::ChartPanel PodPanel(const std::vector<PodCurve>& curves) {
  io::ChartPanel p;
  p.title = "probability of detection against defect size";
  p.x_label = "defect size a (bond stiffness loss)";
  p.y_label = "POD";
  io::ChartLine ninety;
  ninety.label = "POD 0.9";
  ninety.value = 0.9;
  ninety.colour = io::kChartGrey;
  ninety.style = io::LineStyle::kDotted;
  p.hlines.push_back(ninety);
  double lo = 1.0, hi = 0.0;
  for (const PodCurve& c : curves)
    for (const auto& h : c.data) lo = std::min(lo, h.size), hi = std::max(hi, h.size);
  if (!(hi > lo)) lo = 0.01, hi = 1.0;
  for (std::size_t k = 0; k < curves.size(); ++k) {
    const PodCurve& c = curves[k];
    const io::Colour colour = kColours[k % 6];
    io::ChartSeries hits = Series(c.label + " hit/miss", colour);
    hits.line = false;
    hits.markers = true;
    hits.marker_radius = 1.8;
    for (const auto& h : c.data) {
      hits.x.push_back(h.size);
      hits.y.push_back(h.hit ? 1.0 : 0.0);
    }
    p.series.push_back(hits);
    if (!c.fit.usable) continue;
    io::ChartSeries pod = Series(c.label + " POD", colour);
    io::ChartSeries bound = Series(c.label + " lower bound", colour);
    bound.style = io::LineStyle::kDashed;
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
      io::ChartSeries mark = Series(c.label + " a90/95 " + Fixed(c.fit.a90_95_lr), colour,
                                    {c.fit.a90_95_lr, c.fit.a90_95_lr}, {0.0, 1.0});
      mark.width = 2.5;
      p.series.push_back(mark);
    }
  }
  return p;
}

io::ChartPanel F0Panel(const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits) {
  io::ChartPanel p;
  p.title = "fitted f0 per class against the taught limits";
  p.x_label = "f0 (Hz)";
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
    io::ChartSeries s =
        Series(g.label + " (" + std::to_string(g.f0_hz.size()) + ")", kColours[k % 6]);
    for (std::size_t b = 0; b < share.size(); ++b) {  // a step line per bin
      s.x.insert(s.x.end(), {lo + b, lo + b + 1.0});
      s.y.insert(s.y.end(), {share[b], share[b]});
      top = std::max(top, share[b]);
    }
    p.series.push_back(s);
  }
  for (const F0Limit& l : limits) {
    io::ChartSeries s = Series(l.label + " " + Fixed(l.f0_hz, 2) + " Hz", io::kChartBlack,
                               {l.f0_hz, l.f0_hz}, {0.0, top});
    s.width = 2.5;
    p.series.push_back(s);
  }
  return p;
}

}  // namespace

io::Chart PodChart(const std::string& title, const std::vector<PodCurve>& curves,
                   const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits) {
  io::Chart chart;
  chart.title = title;
  chart.panels.push_back(PodPanel(curves));
  bool any_f0 = false;
  for (const F0Group& g : groups) any_f0 = any_f0 || !g.f0_hz.empty();
  if (any_f0) chart.panels.push_back(F0Panel(groups, limits));
  return chart;
}

std::string PodSvg(const std::string& title, const std::vector<PodCurve>& curves,
                   const std::vector<F0Group>& groups, const std::vector<F0Limit>& limits) {
  return io::RenderChartSvg(PodChart(title, curves, groups, limits));
}

void WritePodSvg(const std::string& path, const std::string& title,
                 const std::vector<PodCurve>& curves, const std::vector<F0Group>& groups,
                 const std::vector<F0Limit>& limits) {
  try {
    io::WriteChart(path, PodChart(title, curves, groups, limits));
  } catch (const io::FileError&) {
    throw std::runtime_error("cannot write the POD figure to '" + path + "'");
  }
}

}  // namespace eol::station::cli
