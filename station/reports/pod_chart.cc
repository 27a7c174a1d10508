#include "station/reports/pod_chart.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "analysis/text.h"
#include "drivers/io/chart.h"
#include "drivers/io/file_error.h"

namespace eol::station {
namespace {

// f0 values beyond any motor this station tests are input errors; the figure's f0 panel keeps
// at most this many bins however far apart the values are.
constexpr double kMaxF0Hz = 1e5;
constexpr double kMaxF0Bins = 500.0;

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream in(line);
  std::string cell;
  while (std::getline(in, cell, ',')) out.push_back(cell);
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

double ParseNumber(const std::string& text, const std::string& where) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != text.size() || !std::isfinite(v))
    throw std::runtime_error(where + ": '" + text + "' is not a number");
  return v;
}

// A line without its CR (files saved on Windows, browser uploads) and, on the first line,
// without a UTF-8 byte-order mark.
bool NextLine(std::istream& in, std::string* line, bool first) {
  if (!std::getline(in, *line)) return false;
  if (!line->empty() && line->back() == '\r') line->pop_back();
  if (first && line->rfind("\xEF\xBB\xBF", 0) == 0) line->erase(0, 3);
  return true;
}

}  // namespace

HitsTable ParseHits(std::istream& in, const std::string& path) {
  std::string line;
  if (!NextLine(in, &line, true)) throw std::runtime_error(path + ": empty (no header)");
  const std::vector<std::string> header = SplitCsv(line);
  std::map<std::string, std::size_t> col;
  for (std::size_t i = 0; i < header.size(); ++i) col[header[i]] = i;
  for (const char* need : {"size", "hit"})
    if (!col.count(need))
      throw std::runtime_error(path + ": the header has no column '" + need +
                               "' (needs size and hit; class and f0_hz optional)");
  HitsTable h;
  for (int n = 2; NextLine(in, &line, false); ++n) {
    if (line.empty()) continue;
    const std::vector<std::string> cells = SplitCsv(line);
    const std::string where = path + ":" + std::to_string(n);
    auto cell = [&](const std::string& name) -> std::string {
      const std::size_t i = col.at(name);
      if (i >= cells.size()) throw std::runtime_error(where + ": no value in column " + name);
      return cells[i];
    };
    const std::string cls = col.count("class") ? cell("class") : "all";
    const double size = ParseNumber(cell("size"), where + " size");
    const std::string hit = cell("hit");
    if (hit != "0" && hit != "1") throw std::runtime_error(where + ": hit must be 0 or 1");
    if (size < 0.0) throw std::runtime_error(where + ": size must be >= 0");
    if (size > 0.0) h.defective[cls].push_back({size, hit == "1"});
    if (col.count("f0_hz") && col.at("f0_hz") < cells.size() && !cells[col.at("f0_hz")].empty()) {
      const double f0 = ParseNumber(cells[col.at("f0_hz")], where + " f0_hz");
      if (!(f0 > 0.0 && f0 <= kMaxF0Hz))
        throw std::runtime_error(where + ": f0_hz must be in (0, 100000] Hz");
      h.f0_hz[cls].push_back(f0);
    }
  }
  if (h.defective.empty())
    throw std::runtime_error(path + ": no defective unit (size > 0): nothing to fit");
  return h;
}

HitsTable ReadHitsFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("cannot read the hits file '" + path + "'");
  return ParseHits(in, path);
}

std::vector<PodCurve> FitPodCurves(const HitsTable& hits, const analysis::PodOptions& options) {
  std::vector<PodCurve> curves;
  for (const auto& [cls, data] : hits.defective)
    curves.push_back({cls, analysis::FitPod(data, options), data});
  return curves;
}

std::vector<F0Group> F0Groups(const HitsTable& hits) {
  std::vector<F0Group> groups;
  for (const auto& [cls, f0] : hits.f0_hz) groups.push_back({cls, f0});
  return groups;
}

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
  return analysis::Fixed(v, digits);
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
  // 1 Hz bins; wider ones (whole Hz) when the values span more than kMaxF0Bins of them.
  const double width = std::max(1.0, std::ceil((hi - lo + 1.0) / kMaxF0Bins));
  lo = std::floor(lo);
  const auto bins = static_cast<std::size_t>(std::floor((hi - lo) / width)) + 1;
  if (width > 1.0) p.y_label = "share per " + Fixed(width, 0) + " Hz";
  double top = 0.0;
  for (std::size_t k = 0; k < groups.size(); ++k) {
    const F0Group& g = groups[k];
    if (g.f0_hz.empty()) continue;
    std::vector<double> share(bins, 0.0);
    for (double v : g.f0_hz)
      share[std::min(bins - 1, static_cast<std::size_t>((v - lo) / width))] += 1.0 / g.f0_hz.size();
    io::ChartSeries s =
        Series(g.label + " (" + std::to_string(g.f0_hz.size()) + ")", kColours[k % 6]);
    for (std::size_t b = 0; b < share.size(); ++b) {  // a step line per bin
      s.x.insert(s.x.end(), {lo + b * width, lo + (b + 1) * width});
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

}  // namespace eol::station
