// Charts for engineers, drawn with cairo (Debian's libcairo2) to SVG or PNG: stacked panels,
// each with its own axes (linear or log, "nice" ticks of 1, 2, 5 x 10^k; decades on log
// axes), line and scatter series, histogram bars, horizontal and vertical limit lines with
// their labels, shaded bands (a tolerance window, a mask), a legend to the right and note
// lines (capability, alarms) in the panel's corner. Numbers are written with std::to_chars,
// so a chart does not depend on the machine's locale.
//
// Cairo's SVG surface writes text as glyph outlines; so that a reader, a screen reader or a
// test can find the words, the SVG also carries them as <title> (the chart's title) and
// <desc> (every string drawn, one per line, in drawing order).
//
// Sizes are in CSS pixels (the SVG's points: cairo writes width="960pt").
#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

struct _cairo;  // cairo_t, as <cairo.h> names it

namespace eol::io {

struct Colour {
  double r = 0.0, g = 0.0, b = 0.0;  // 0..1
};
inline constexpr Colour kChartBlue{0.122, 0.467, 0.706};
inline constexpr Colour kChartOrange{1.0, 0.498, 0.055};
inline constexpr Colour kChartGreen{0.173, 0.627, 0.173};
inline constexpr Colour kChartRed{0.839, 0.153, 0.157};
inline constexpr Colour kChartPurple{0.580, 0.404, 0.741};
inline constexpr Colour kChartGrey{0.45, 0.45, 0.45};
inline constexpr Colour kChartBlack{0.0, 0.0, 0.0};

enum class LineStyle { kSolid, kDashed, kDotted };

struct ChartSeries {
  std::string label;  // legend entry; empty: none
  Colour colour = kChartBlue;
  std::vector<double> x, y;  // same length; a non-finite point breaks the line
  bool line = true;
  bool markers = false;
  double width = 1.5;
  double marker_radius = 2.5;
  LineStyle style = LineStyle::kSolid;
};

// A limit or centre line across the panel: y = value (hlines) or x = value (vlines). The
// label is drawn beside the line and in the legend.
struct ChartLine {
  std::string label;
  double value = 0.0;
  Colour colour = kChartBlack;
  LineStyle style = LineStyle::kDashed;
  double width = 1.5;
};

// A shaded interval: lo <= y <= hi (hbands) or lo <= x <= hi (vbands). A non-finite end
// reaches the panel's edge.
struct ChartBand {
  std::string label;
  double lo = 0.0, hi = 0.0;
  Colour colour = kChartGreen;
  double alpha = 0.15;
};

struct ChartBar {
  double x_lo = 0.0, x_hi = 0.0, height = 0.0;
};
struct ChartBars {
  std::string label;
  Colour colour = kChartBlue;
  std::vector<ChartBar> bars;
};
// Counts of `values` in `bins` equal bins over [lo, hi] (values outside are left out).
// Throws std::invalid_argument unless bins >= 1 and lo < hi.
ChartBars Histogram(const std::vector<double>& values, double lo, double hi, int bins);

struct ChartPanel {
  std::string title;  // above the panel
  std::string x_label, y_label;
  bool log_x = false, log_y = false;  // non-positive values are skipped on a log axis
  std::vector<ChartBand> hbands, vbands;
  std::vector<ChartBars> bars;
  std::vector<ChartSeries> series;
  std::vector<ChartLine> hlines, vlines;
  std::vector<std::string> notes;  // lines in the top-left corner
  // Fixed ranges; otherwise from the data, the lines and the finite band ends.
  std::optional<std::pair<double, double>> x_range, y_range;
};

struct Chart {
  std::string title;
  std::vector<ChartPanel> panels;
  int width_px = 960;
  int panel_height_px = 280;
};

// Label rows that do not overlap: `desired` are the baselines (pixels, down is +) where labels
// of one text height would go; returns the baselines moved apart by at least `gap`, in the
// same order, as little as possible, all within [top, bottom] when they fit (pushed down from
// the top, then back up from the bottom). The horizontal limit lines' labels are placed so
// that "UCL 417.8" and "USL 420 Hz" two pixels apart do not overwrite each other.
std::vector<double> SpreadLabels(const std::vector<double>& desired, double gap, double top,
                                 double bottom);

// The documents. Throw std::invalid_argument for a chart without panels and
// std::runtime_error when cairo fails.
std::string RenderChartSvg(const Chart& chart);
std::string RenderChartPng(const Chart& chart);
// Draws the chart on a cairo context the caller owns (a page of a PDF report,
// station/reports/unit_report.h) with its top-left corner at the context's origin, within
// ChartWidth x ChartHeight units (clipped there, its white background included); returns the
// strings drawn. Throws as the renderers do.
std::vector<std::string> DrawChart(_cairo* cr, const Chart& chart);
double ChartWidth(const Chart& chart);
double ChartHeight(const Chart& chart);

// SVG, or PNG for a path ending in ".png"; throws FileError (file_error.h) when the file
// cannot be written.
void WriteChart(const std::string& path, const Chart& chart);

}  // namespace eol::io
