#include "station/reports/curve_chart.h"

#include <charconv>
#include <cmath>

namespace eol::station {
namespace {

std::string Num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
  return std::string(buf, r.ptr);
}

void AddWindow(const CurvePlot& p, io::ChartPanel& panel) {
  const analysis::Limit& w = p.resonance_window;
  if (w.lo || w.hi) {
    io::ChartBand band;
    band.lo = w.lo ? *w.lo : -INFINITY;
    band.hi = w.hi ? *w.hi : INFINITY;
    band.label = "resonance window [" + (w.lo ? Num(*w.lo) : std::string("-")) + ", " +
                 (w.hi ? Num(*w.hi) : std::string("-")) + "] Hz";
    panel.vbands.push_back(band);
    for (const auto& [edge, name] : {std::pair{w.lo, "f0 lo "}, std::pair{w.hi, "f0 hi "}})
      if (edge) {
        io::ChartLine l;
        l.label = name + Num(*edge) + " Hz";
        l.value = *edge;
        l.colour = io::kChartGreen;
        l.style = io::LineStyle::kSolid;
        panel.vlines.push_back(l);
      }
  }
  if (p.f0_hz) {
    io::ChartLine l;
    l.label = "fitted f0 " + Num(*p.f0_hz) + " Hz";
    l.value = *p.f0_hz;
    l.colour = io::kChartOrange;
    l.style = io::LineStyle::kDotted;
    panel.vlines.push_back(l);
  }
}

void AddMasks(const CurvePlot& p, analysis::MaskQuantity q, io::ChartPanel& panel) {
  for (const analysis::CurveMask& m : p.masks) {
    if (m.quantity != q) continue;
    io::ChartSeries lo, hi;
    lo.label = "mask " + m.name + " lo";
    hi.label = "mask " + m.name + " hi";
    for (io::ChartSeries* s : {&lo, &hi}) {
      s->colour = io::kChartRed;
      s->style = io::LineStyle::kDashed;
      s->width = 1.5;
    }
    for (const analysis::MaskPoint& pt : m.points) {
      lo.x.push_back(pt.f_hz);
      lo.y.push_back(pt.lo ? *pt.lo : NAN);
      hi.x.push_back(pt.f_hz);
      hi.y.push_back(pt.hi ? *pt.hi : NAN);
    }
    for (io::ChartSeries* s : {&lo, &hi}) {
      bool any = false;
      for (double v : s->y) any = any || std::isfinite(v);
      if (any) panel.series.push_back(*s);
    }
  }
}

io::ChartPanel Panel(const CurvePlot& p, bool abs) {
  io::ChartPanel panel;
  panel.title = abs ? "|Z| measured and fitted" : "Re Z measured and fitted";
  panel.x_label = "frequency (Hz)";
  panel.y_label = abs ? "|Z| (ohm)" : "Re Z (ohm)";
  AddWindow(p, panel);
  io::ChartSeries measured;
  measured.label = abs ? "measured |Z|" : "measured Re Z";
  measured.x = p.freq_hz;
  for (const auto& z : p.measured) measured.y.push_back(abs ? std::abs(z) : z.real());
  measured.line = false;
  measured.markers = true;
  measured.marker_radius = 1.8;
  panel.series.push_back(measured);
  if (!p.model.empty()) {
    io::ChartSeries model;
    model.label = abs ? "fitted model |Z|" : "fitted model Re Z";
    model.colour = io::kChartOrange;
    model.width = 2.0;
    model.x = p.model_freq_hz;
    for (const auto& z : p.model) model.y.push_back(abs ? std::abs(z) : z.real());
    panel.series.push_back(model);
  }
  AddMasks(p, abs ? analysis::MaskQuantity::kAbsOhm : analysis::MaskQuantity::kReOhm, panel);
  if (abs) panel.notes = p.notes;
  return panel;
}

}  // namespace

io::Chart CurveChart(const CurvePlot& p) {
  io::Chart c;
  c.title = p.title;
  c.panels = {Panel(p, true), Panel(p, false)};
  return c;
}

}  // namespace eol::station
