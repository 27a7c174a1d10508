#include "drivers/io/chart.h"

#include <cairo-svg.h>
#include <cairo.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>
#include <tuple>

#include "drivers/io/axis_ticks.h"
#include "drivers/io/file_error.h"

namespace eol::io {
namespace {

// Layout of one panel (pixels): title band above, tick labels and axis label below, legend
// column to the right.
constexpr double kLeft = 84, kRight = 230, kTitleH = 44, kPanelTitleH = 22, kBelow = 44;
constexpr double kFont = 12, kTitleFont = 16, kPanelTitleFont = 13, kSmallFont = 10.5;

std::string Num(double v) {
  char buf[32];
  const auto r = std::to_chars(buf, buf + sizeof buf, v, std::chars_format::general, 6);
  return std::string(buf, r.ptr);
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '&')
      out += "&amp;";
    else if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else
      out += c;
  }
  return out;
}

struct Axis {
  double lo = 0.0, hi = 1.0;
  bool log = false;
  double px_lo = 0.0, px_hi = 1.0;  // pixels of lo and hi
  double Map(double v) const {
    const double a = log ? std::log10(lo) : lo, b = log ? std::log10(hi) : hi;
    return px_lo + ((log ? std::log10(v) : v) - a) / (b - a) * (px_hi - px_lo);
  }
  bool Valid(double v) const { return std::isfinite(v) && (!log || v > 0.0); }
  // A band end: non-finite reaches the edge.
  double MapEdge(double v, bool low_end) const {
    if (!std::isfinite(v) || (log && v <= 0.0)) return low_end ? px_lo : px_hi;
    return Map(v);
  }
};

struct Extent {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void Add(double v, bool log) {
    if (!std::isfinite(v) || (log && v <= 0.0)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  // Padded by `pad` of the span (in decades on a log axis); a point or nothing gets a span.
  std::pair<double, double> Range(bool log, double pad) const {
    if (!std::isfinite(lo)) return {log ? 0.1 : 0.0, 1.0};
    if (log) {
      const double a = std::log10(lo), b = std::log10(hi), d = b > a ? pad * (b - a) : 0.5;
      return {std::pow(10.0, a - d), std::pow(10.0, b + d)};
    }
    if (hi <= lo) {
      const double d = std::max(std::abs(lo) * 0.1, 1e-9);
      return {lo - d, hi + d};
    }
    const double d = pad * (hi - lo);
    return {lo - d, hi + d};
  }
};

// Records every string drawn (for the SVG's <desc>) and draws it.
class Painter {
 public:
  explicit Painter(cairo_t* cr) : cr_(cr) {
    cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
  }
  cairo_t* cr() const { return cr_; }
  const std::vector<std::string>& texts() const { return texts_; }

  // anchor: 0 left, 0.5 centre, 1 right of x; y is the baseline. `angle` in radians.
  void Text(const std::string& s, double x, double y, double size, double anchor = 0.0,
            Colour c = kChartBlack, double angle = 0.0, bool bold = false) {
    if (s.empty()) return;
    texts_.push_back(s);
    cairo_save(cr_);
    cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr_, s.c_str(), &e);
    cairo_translate(cr_, x, y);
    cairo_rotate(cr_, angle);
    cairo_move_to(cr_, -anchor * e.x_advance, 0.0);
    SetColour(c);
    cairo_show_text(cr_, s.c_str());
    cairo_restore(cr_);
  }
  double TextWidth(const std::string& s, double size, bool bold = false) {
    cairo_save(cr_);
    cairo_select_font_face(cr_, "sans-serif", CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size);
    cairo_text_extents_t e;
    cairo_text_extents(cr_, s.c_str(), &e);
    cairo_restore(cr_);
    return e.x_advance;
  }
  void SetColour(Colour c, double alpha = 1.0) { cairo_set_source_rgba(cr_, c.r, c.g, c.b, alpha); }
  void SetStroke(double width, LineStyle style) {
    cairo_set_line_width(cr_, width);
    if (style == LineStyle::kDashed) {
      const double d[] = {6.0, 4.0};
      cairo_set_dash(cr_, d, 2, 0.0);
    } else if (style == LineStyle::kDotted) {
      const double d[] = {1.5, 3.0};
      cairo_set_dash(cr_, d, 2, 0.0);
    } else {
      cairo_set_dash(cr_, nullptr, 0, 0.0);
    }
  }
  void Line(double x0, double y0, double x1, double y1) {
    cairo_move_to(cr_, x0, y0);
    cairo_line_to(cr_, x1, y1);
    cairo_stroke(cr_);
  }

 private:
  cairo_t* cr_;
  std::vector<std::string> texts_;
};

double Height(const Chart& c) {
  return kTitleH + static_cast<double>(c.panels.size()) * c.panel_height_px;
}

void LegendEntry(Painter& p, double x, double* y, const std::string& label, Colour c,
                 LineStyle style, double width, bool line, bool marker, bool box, double alpha) {
  if (label.empty()) return;
  cairo_t* cr = p.cr();
  const double mid = *y - 4.0;
  if (box) {
    p.SetColour(c, std::max(alpha, 0.3));
    cairo_rectangle(cr, x, mid - 5.0, 22.0, 10.0);
    cairo_fill(cr);
  }
  if (line) {
    p.SetColour(c);
    p.SetStroke(std::max(width, 1.5), style);
    p.Line(x, mid, x + 22.0, mid);
  }
  if (marker) {
    p.SetColour(c);
    cairo_arc(cr, x + 11.0, mid, 3.0, 0.0, 2.0 * M_PI);
    cairo_fill(cr);
  }
  // Long labels wrap onto a second line at a space.
  const double room = kRight - 44.0;
  std::string first = label, rest;
  if (p.TextWidth(label, kSmallFont) > room) {
    for (std::size_t cut = label.size(); cut > 0; --cut) {
      if (label[cut - 1] != ' ') continue;
      if (p.TextWidth(label.substr(0, cut - 1), kSmallFont) <= room) {
        first = label.substr(0, cut - 1);
        rest = label.substr(cut);
        break;
      }
    }
  }
  p.Text(first, x + 28.0, *y, kSmallFont);
  if (!rest.empty()) {
    *y += 13.0;
    p.Text(rest, x + 28.0, *y, kSmallFont);
  }
  *y += 16.0;
}

// Pixels of a panel's plot area (inside the frame).
struct PlotArea {
  double left = 0.0, right = 0.0, top = 0.0, bottom = 0.0;
  double Width() const { return right - left; }
  double Height() const { return bottom - top; }
};

// Height of the notes box in the top-left corner (0 without notes).
double NotesHeight(const ChartPanel& panel) {
  return panel.notes.empty() ? 0.0 : 14.0 * static_cast<double>(panel.notes.size()) + 6.0;
}

// The extents of everything drawn: series, bars, lines and band ends.
void DataExtents(const ChartPanel& panel, Extent* ex, Extent* ey) {
  for (const ChartSeries& s : panel.series) {
    for (double v : s.x) ex->Add(v, panel.log_x);
    for (double v : s.y) ey->Add(v, panel.log_y);
  }
  for (const ChartBars& b : panel.bars)
    for (const ChartBar& bar : b.bars) {
      ex->Add(bar.x_lo, panel.log_x);
      ex->Add(bar.x_hi, panel.log_x);
      ey->Add(bar.height, panel.log_y);
      ey->Add(0.0, panel.log_y);
    }
  for (const ChartLine& l : panel.hlines) ey->Add(l.value, panel.log_y);
  for (const ChartLine& l : panel.vlines) ex->Add(l.value, panel.log_x);
  for (const ChartBand& b : panel.hbands) ey->Add(b.lo, panel.log_y), ey->Add(b.hi, panel.log_y);
  for (const ChartBand& b : panel.vbands) ex->Add(b.lo, panel.log_x), ex->Add(b.hi, panel.log_x);
}

// The panel's axes: fixed ranges or the padded extents, mapped onto the plot area.
void SetUpAxes(const ChartPanel& panel, const PlotArea& area, Axis* x, Axis* y) {
  Extent ex, ey;
  DataExtents(panel, &ex, &ey);
  x->log = panel.log_x;
  y->log = panel.log_y;
  std::tie(x->lo, x->hi) = panel.x_range ? *panel.x_range : ex.Range(x->log, 0.02);
  std::tie(y->lo, y->hi) = panel.y_range ? *panel.y_range : ey.Range(y->log, 0.06);
  if (!panel.bars.empty() && !y->log && !panel.y_range) y->lo = std::max(y->lo, 0.0);
  // Head room above the data for the notes box and the vertical lines' labels, so that
  // neither hides a point or a bar (linear axes whose range is not fixed).
  const double head_px = NotesHeight(panel) + 13.0 * static_cast<double>(panel.vlines.size()) +
                         (panel.vlines.empty() ? 0 : 4);
  if (!y->log && !panel.y_range && head_px > 0.0) {
    const double room = area.bottom - area.top;
    if (head_px < 0.6 * room) y->hi += (y->hi - y->lo) * head_px / (room - head_px);
  }
  x->px_lo = area.left;
  x->px_hi = area.right;
  y->px_lo = area.bottom;
  y->px_hi = area.top;
}

void ClipToPlot(cairo_t* cr, const PlotArea& area) {
  cairo_save(cr);
  cairo_rectangle(cr, area.left, area.top, area.Width(), area.Height());
  cairo_clip(cr);
}

// Shaded bands, behind everything.
void DrawBands(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
               const Axis& y) {
  cairo_t* cr = p.cr();
  ClipToPlot(cr, area);
  for (const ChartBand& b : panel.hbands) {
    const double a = y.MapEdge(b.lo, true), c = y.MapEdge(b.hi, false);
    p.SetColour(b.colour, b.alpha);
    cairo_rectangle(cr, area.left, std::min(a, c), area.Width(), std::abs(a - c));
    cairo_fill(cr);
  }
  for (const ChartBand& b : panel.vbands) {
    const double a = x.MapEdge(b.lo, true), c = x.MapEdge(b.hi, false);
    p.SetColour(b.colour, b.alpha);
    cairo_rectangle(cr, std::min(a, c), area.top, std::max(std::abs(a - c), 1.0), area.Height());
    cairo_fill(cr);
  }
  cairo_restore(cr);
}

// Grid lines, ticks with their numbers, and the axis labels.
void DrawGrid(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
              const Axis& y) {
  const std::vector<double> xt = x.log ? LogTicks(x.lo, x.hi) : LinearTicks(x.lo, x.hi, 8);
  const std::vector<double> yt = y.log ? LogTicks(y.lo, y.hi) : LinearTicks(y.lo, y.hi, 5);
  p.SetStroke(1.0, LineStyle::kSolid);
  for (double t : yt) {
    const double py = y.Map(t);
    p.SetColour({0.88, 0.88, 0.88});
    p.Line(area.left, py, area.right, py);
    p.SetColour(kChartBlack);
    p.Line(area.left - 4.0, py, area.left, py);
    p.Text(Num(t), area.left - 7.0, py + 4.0, kFont, 1.0);
  }
  for (double t : xt) {
    const double px = x.Map(t);
    p.SetColour({0.92, 0.92, 0.92});
    p.Line(px, area.top, px, area.bottom);
    p.SetColour(kChartBlack);
    p.Line(px, area.bottom, px, area.bottom + 4.0);
    p.Text(Num(t), px, area.bottom + 17.0, kFont, 0.5);
  }
  p.Text(panel.x_label, (area.left + area.right) / 2.0, area.bottom + 35.0, kFont, 0.5);
  p.Text(panel.y_label, 20.0, (area.top + area.bottom) / 2.0, kFont, 0.5, kChartBlack, -M_PI / 2.0);
}

void DrawBars(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
              const Axis& y) {
  cairo_t* cr = p.cr();
  for (const ChartBars& b : panel.bars)
    for (const ChartBar& bar : b.bars) {
      if (!x.Valid(bar.x_lo) || !x.Valid(bar.x_hi) || !(bar.height > 0.0)) continue;
      const double a = x.Map(bar.x_lo), c = x.Map(bar.x_hi);
      const double base = y.log ? area.bottom : y.Map(std::max(0.0, y.lo));
      const double h = y.Valid(bar.height) ? y.Map(bar.height) : base;
      p.SetColour(b.colour, 0.55);
      cairo_rectangle(cr, a, h, c - a, base - h);
      cairo_fill_preserve(cr);
      p.SetColour(b.colour);
      p.SetStroke(0.8, LineStyle::kSolid);
      cairo_stroke(cr);
    }
}

// One series: its line (broken at invalid points) and its markers.
void DrawSeries(Painter& p, const ChartSeries& s, const Axis& x, const Axis& y) {
  cairo_t* cr = p.cr();
  p.SetColour(s.colour);
  p.SetStroke(s.width, s.style);
  if (s.line) {
    bool open = false;
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!x.Valid(s.x[i]) || !y.Valid(s.y[i])) {
        open = false;
        continue;
      }
      if (open)
        cairo_line_to(cr, x.Map(s.x[i]), y.Map(s.y[i]));
      else
        cairo_move_to(cr, x.Map(s.x[i]), y.Map(s.y[i]));
      open = true;
    }
    cairo_stroke(cr);
  }
  if (s.markers)
    for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!x.Valid(s.x[i]) || !y.Valid(s.y[i])) continue;
      cairo_new_sub_path(cr);
      cairo_arc(cr, x.Map(s.x[i]), y.Map(s.y[i]), s.marker_radius, 0.0, 2.0 * M_PI);
      cairo_fill(cr);
    }
}

void DrawLimitLines(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
                    const Axis& y) {
  for (const ChartLine& l : panel.hlines) {
    if (!y.Valid(l.value)) continue;
    const double py = y.Map(l.value);
    p.SetColour(l.colour);
    p.SetStroke(l.width, l.style);
    p.Line(area.left, py, area.right, py);
  }
  for (const ChartLine& l : panel.vlines) {
    if (!x.Valid(l.value)) continue;
    const double px = x.Map(l.value);
    p.SetColour(l.colour);
    p.SetStroke(l.width, l.style);
    p.Line(px, area.top, px, area.bottom);
  }
}

// Bars, series and limit lines, clipped to the plot area.
void DrawData(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
              const Axis& y) {
  ClipToPlot(p.cr(), area);
  DrawBars(p, panel, area, x, y);
  for (const ChartSeries& s : panel.series) DrawSeries(p, s, x, y);
  DrawLimitLines(p, panel, area, x, y);
  cairo_restore(p.cr());
}

// Line labels beside their lines, inside the frame; the horizontal lines' labels spread so
// that none overwrites another.
void DrawLineLabels(Painter& p, const ChartPanel& panel, const PlotArea& area, const Axis& x,
                    const Axis& y) {
  std::vector<const ChartLine*> shown;
  std::vector<double> want;
  for (const ChartLine& l : panel.hlines)
    if (y.Valid(l.value) && l.value >= y.lo && l.value <= y.hi && !l.label.empty()) {
      shown.push_back(&l);
      want.push_back(y.Map(l.value) - 3.0);
    }
  const std::vector<double> at =
      SpreadLabels(want, kSmallFont + 2.0, area.top + kSmallFont, area.bottom - 3.0);
  for (std::size_t i = 0; i < shown.size(); ++i)
    p.Text(shown[i]->label, area.right - 4.0, at[i], kSmallFont, 1.0, shown[i]->colour);
  double label_y = area.top + NotesHeight(panel) + 15.0;  // one row per vertical line
  for (const ChartLine& l : panel.vlines)
    if (x.Valid(l.value) && l.value >= x.lo && l.value <= x.hi) {
      // Right of the line, or left of it when it would leave the frame.
      const double px = x.Map(l.value);
      const bool left = px + 3.0 + p.TextWidth(l.label, kSmallFont) > area.right;
      p.Text(l.label, left ? px - 3.0 : px + 3.0, label_y, kSmallFont, left ? 1.0 : 0.0, l.colour);
      label_y += 13.0;
    }
}

void DrawFrame(Painter& p, const PlotArea& area) {
  p.SetColour({0.2, 0.2, 0.2});
  p.SetStroke(1.0, LineStyle::kSolid);
  cairo_rectangle(p.cr(), area.left, area.top, area.Width(), area.Height());
  cairo_stroke(p.cr());
}

// Notes on a white box in the top-left corner.
void DrawNotes(Painter& p, const ChartPanel& panel, const PlotArea& area) {
  if (panel.notes.empty()) return;
  cairo_t* cr = p.cr();
  double w = 0.0;
  for (const std::string& n : panel.notes) w = std::max(w, p.TextWidth(n, kSmallFont));
  const double h = 14.0 * static_cast<double>(panel.notes.size()) + 6.0;
  cairo_set_source_rgba(cr, 1.0, 1.0, 1.0, 0.85);
  cairo_rectangle(cr, area.left + 6.0, area.top + 6.0, w + 10.0, h);
  cairo_fill(cr);
  double ny = area.top + 19.0;
  for (const std::string& n : panel.notes) {
    p.Text(n, area.left + 11.0, ny, kSmallFont);
    ny += 14.0;
  }
}

void DrawLegend(Painter& p, const ChartPanel& panel, const PlotArea& area) {
  double ly = area.top + 10.0;
  const double lx = area.right + 12.0;
  for (const ChartBand& b : panel.hbands)
    LegendEntry(p, lx, &ly, b.label, b.colour, LineStyle::kSolid, 0, false, false, true, b.alpha);
  for (const ChartBand& b : panel.vbands)
    LegendEntry(p, lx, &ly, b.label, b.colour, LineStyle::kSolid, 0, false, false, true, b.alpha);
  for (const ChartBars& b : panel.bars)
    LegendEntry(p, lx, &ly, b.label, b.colour, LineStyle::kSolid, 0, false, false, true, 0.55);
  for (const ChartSeries& s : panel.series)
    LegendEntry(p, lx, &ly, s.label, s.colour, s.style, s.width, s.line, s.markers, false, 1.0);
  for (const ChartLine& l : panel.hlines)
    LegendEntry(p, lx, &ly, l.label, l.colour, l.style, l.width, true, false, false, 1.0);
  for (const ChartLine& l : panel.vlines)
    LegendEntry(p, lx, &ly, l.label, l.colour, l.style, l.width, true, false, false, 1.0);
}

void DrawPanel(Painter& p, const ChartPanel& panel, double top, double width, double height) {
  const PlotArea area{kLeft, width - kRight, top + kPanelTitleH, top + height - kBelow};
  Axis x, y;
  SetUpAxes(panel, area, &x, &y);
  p.Text(panel.title, area.left, top + 15.0, kPanelTitleFont, 0.0, kChartBlack, 0.0, true);
  DrawBands(p, panel, area, x, y);
  DrawGrid(p, panel, area, x, y);
  DrawData(p, panel, area, x, y);
  DrawLineLabels(p, panel, area, x, y);
  DrawFrame(p, area);
  DrawNotes(p, panel, area);
  DrawLegend(p, panel, area);
}

// Draws the whole chart on `cr`; returns the strings drawn.
std::vector<std::string> Draw(cairo_t* cr, const Chart& c) {
  Painter p(cr);
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_paint(cr);
  // A long title (a file path) shrinks to the chart's width rather than leave it.
  const double room = c.width_px - 20.0, wide = p.TextWidth(c.title, kTitleFont, true);
  const double size = wide > room ? std::max(8.0, kTitleFont * room / wide) : kTitleFont;
  p.Text(c.title, c.width_px / 2.0, 27.0, size, 0.5, kChartBlack, 0.0, true);
  for (std::size_t i = 0; i < c.panels.size(); ++i)
    DrawPanel(p, c.panels[i], kTitleH + static_cast<double>(i) * c.panel_height_px, c.width_px,
              c.panel_height_px);
  return p.texts();
}

void Check(const Chart& c) {
  if (c.panels.empty()) throw std::invalid_argument("chart '" + c.title + "' has no panels");
  if (c.width_px < kLeft + kRight + 100 || c.panel_height_px < 120)
    throw std::invalid_argument("chart '" + c.title + "' is too small to draw");
}

cairo_status_t Append(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

struct SurfaceDeleter {
  void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
  void operator()(cairo_t* c) const { cairo_destroy(c); }
};

void ThrowIf(cairo_status_t status, const char* what) {
  if (status != CAIRO_STATUS_SUCCESS)
    throw std::runtime_error(std::string("cairo ") + what + ": " + cairo_status_to_string(status));
}

}  // namespace

std::vector<double> SpreadLabels(const std::vector<double>& desired, double gap, double top,
                                 double bottom) {
  std::vector<std::size_t> order(desired.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return desired[a] < desired[b]; });
  std::vector<double> y(desired.size());
  double prev = -INFINITY;
  for (const std::size_t i : order) {  // top to bottom: push down what is too close
    y[i] = std::max({desired[i], top, prev + gap});
    prev = y[i];
  }
  double next = INFINITY;
  for (auto it = order.rbegin(); it != order.rend(); ++it) {  // then back up from the bottom
    y[*it] = std::min({y[*it], bottom, next - gap});
    next = y[*it];
  }
  return y;
}

ChartBars Histogram(const std::vector<double>& values, double lo, double hi, int bins) {
  if (bins < 1 || !(lo < hi)) throw std::invalid_argument("Histogram: needs bins >= 1 and lo < hi");
  ChartBars out;
  const double w = (hi - lo) / bins;
  for (int b = 0; b < bins; ++b) out.bars.push_back({lo + b * w, lo + (b + 1) * w, 0.0});
  for (double v : values) {
    if (!(v >= lo && v <= hi)) continue;
    const int b = std::min(bins - 1, static_cast<int>((v - lo) / w));
    out.bars[static_cast<std::size_t>(b)].height += 1.0;
  }
  return out;
}

std::vector<std::string> DrawChart(cairo_t* cr, const Chart& c) {
  Check(c);
  cairo_save(cr);
  cairo_rectangle(cr, 0.0, 0.0, c.width_px, Height(c));
  cairo_clip(cr);
  std::vector<std::string> texts = Draw(cr, c);
  cairo_restore(cr);
  ThrowIf(cairo_status(cr), "drawing");
  return texts;
}

double ChartWidth(const Chart& c) { return c.width_px; }
double ChartHeight(const Chart& c) { return Height(c); }

std::string RenderChartSvg(const Chart& c) {
  Check(c);
  std::string svg;
  std::vector<std::string> texts;
  {
    std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(
        cairo_svg_surface_create_for_stream(Append, &svg, c.width_px, Height(c)));
    ThrowIf(cairo_surface_status(surface.get()), "SVG surface");
    std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
    texts = Draw(cr.get(), c);
    ThrowIf(cairo_status(cr.get()), "drawing");
    cr.reset();
    cairo_surface_finish(surface.get());
    ThrowIf(cairo_surface_status(surface.get()), "SVG output");
  }
  // Cairo numbers its surfaces with a process-wide counter ("surface6" for the sixth chart
  // drawn); name the drawing's root group "chart" so the same chart gives the same bytes.
  const std::string key = "<g id=\"surface";
  if (const std::size_t at = svg.find(key); at != std::string::npos) {
    const std::size_t id_at = at + 7, id_end = svg.find('"', id_at);
    const std::string id = svg.substr(id_at, id_end - id_at);
    if (svg.find("#" + id + "\"") == std::string::npos) svg.replace(id_at, id.size(), "chart");
  }
  // The words, for readers that cannot read glyph outlines (see the header).
  const std::size_t root = svg.find("<svg");
  const std::size_t end = root == std::string::npos ? root : svg.find('>', root);
  if (end == std::string::npos) throw std::runtime_error("cairo wrote no <svg> element");
  std::string meta = "\n<title>" + XmlEscape(c.title) + "</title>\n<desc>";
  for (const std::string& t : texts) meta += XmlEscape(t) + "\n";
  meta += "</desc>";
  svg.insert(end + 1, meta);
  return svg;
}

std::string RenderChartPng(const Chart& c) {
  Check(c);
  std::string png;
  std::unique_ptr<cairo_surface_t, SurfaceDeleter> surface(cairo_image_surface_create(
      CAIRO_FORMAT_ARGB32, c.width_px, static_cast<int>(std::ceil(Height(c)))));
  ThrowIf(cairo_surface_status(surface.get()), "image surface");
  {
    std::unique_ptr<cairo_t, ContextDeleter> cr(cairo_create(surface.get()));
    Draw(cr.get(), c);
    ThrowIf(cairo_status(cr.get()), "drawing");
  }
  ThrowIf(cairo_surface_write_to_png_stream(surface.get(), Append, &png), "PNG output");
  return png;
}

void WriteChart(const std::string& path, const Chart& chart) {
  const bool png = path.size() >= 4 && path.compare(path.size() - 4, 4, ".png") == 0;
  const std::string data = png ? RenderChartPng(chart) : RenderChartSvg(chart);
  std::ofstream out(path, std::ios::binary);
  if (!out) throw FileError(path, 0, 0, "cannot open for writing");
  out << data;
  out.flush();
  if (!out) throw FileError(path, 0, 0, "write failed");
}

}  // namespace eol::io
