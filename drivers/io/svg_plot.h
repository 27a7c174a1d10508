// A small SVG line-plot writer (no plotting library): stacked panels sharing one x axis,
// line or marker series with a legend, shaded x intervals, linear or log axes with "nice"
// ticks (1, 2, 5 x 10^k steps; decades on log axes). Numbers are written with the classic
// locale, so the file does not depend on the machine's locale.
#pragma once

#include <string>
#include <utility>
#include <vector>

namespace eol::io {

struct SvgSeries {
  std::string label;
  std::string color = "#1f77b4";  // any SVG colour
  std::vector<double> x, y;       // same length; non-finite points break the line
  bool markers = false;           // small circles instead of a line
  double width = 1.5;
  bool dashed = false;
};

struct SvgPanel {
  std::string y_label;
  std::vector<SvgSeries> series;
  bool log_y = false;                             // non-positive y are skipped
  std::vector<std::pair<double, double>> shaded;  // x intervals, shaded behind the series
  std::vector<double> hlines;                     // dotted horizontal reference lines
};

struct SvgFigure {
  std::string title;
  std::string x_label;
  bool log_x = false;
  std::vector<SvgPanel> panels;
  int width_px = 960;
  int panel_height_px = 240;
};

// The SVG document. Throws std::invalid_argument for a figure without panels.
std::string RenderSvg(const SvgFigure& figure);
// Renders and writes; throws FileError (file_error.h) when the file cannot be written.
void WriteSvg(const std::string& path, const SvgFigure& figure);

}  // namespace eol::io
