// The cairo chart writer (drivers/io/chart.h): histogram counts, the words carried in the SVG,
// identical bytes for identical charts, PNG output, and the errors it names.
#include "drivers/io/chart.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <stdexcept>

#include "drivers/io/file_error.h"
#include "tests/support/child_process.h"

namespace eol::io {
namespace {

Chart Sample() {
  Chart c;
  c.title = "a & b <chart>";
  ChartPanel p;
  p.title = "panel one";
  p.x_label = "x (s)";
  p.y_label = "y (V)";
  ChartSeries s;
  s.label = "data";
  s.x = {0.0, 1.0, 2.0, 3.0};
  s.y = {1.0, 3.0, NAN, 2.0};  // the NaN breaks the line
  s.markers = true;
  p.series.push_back(s);
  p.hlines.push_back({"UCL 3.5", 3.5, kChartRed, LineStyle::kDashed, 1.5});
  p.hbands.push_back({"window [0.5, 3]", 0.5, 3.0, kChartGreen, 0.15});
  p.notes.push_back("n 4");
  c.panels.push_back(p);
  return c;
}

TEST(Chart, HistogramCountsValuesInsideTheRange) {
  // Bins of width 1 over [0, 4]: 0.5 -> bin 0; 1 and 1.5 -> bin 1; 4 (the top edge) -> bin 3;
  // -1 and 5 are outside.
  const ChartBars h = Histogram({0.5, 1.0, 1.5, 4.0, -1.0, 5.0}, 0.0, 4.0, 4);
  ASSERT_EQ(h.bars.size(), 4u);
  EXPECT_EQ(h.bars[0].height, 1.0);
  EXPECT_EQ(h.bars[1].height, 2.0);
  EXPECT_EQ(h.bars[2].height, 0.0);
  EXPECT_EQ(h.bars[3].height, 1.0);
  EXPECT_DOUBLE_EQ(h.bars[3].x_lo, 3.0);
  EXPECT_THROW(Histogram({1.0}, 1.0, 1.0, 3), std::invalid_argument);
  EXPECT_THROW(Histogram({1.0}, 0.0, 1.0, 0), std::invalid_argument);
}

TEST(Chart, SvgCarriesTheWordsEscapedAndIsReproducible) {
  const std::string svg = RenderChartSvg(Sample());
  EXPECT_EQ(svg.rfind("<?xml", 0), 0u);
  EXPECT_NE(svg.find("<title>a &amp; b &lt;chart&gt;</title>"), std::string::npos)
      << svg.substr(0, 600);
  for (const char* word :
       {"panel one", "x (s)", "y (V)", "data", "UCL 3.5", "window [0.5, 3]", "n 4"})
    EXPECT_NE(svg.find(std::string("\n") + word + "\n"), std::string::npos) << word;
  EXPECT_NE(svg.find("<use"), std::string::npos);  // glyphs drawn
  EXPECT_EQ(svg, RenderChartSvg(Sample()));
}

// "UCL 417.8" and "USL 420 Hz" 5 px apart (the overlap a quality engineer saw), a third label
// far away, and a crowd at the bottom edge: the rows keep their order, stay 12 px apart, move
// as little as needed and stay inside the frame.
TEST(Chart, LineLabelsNeverOverlap) {
  const std::vector<double> two = SpreadLabels({100.0, 95.0, 200.0}, 12.0, 20.0, 280.0);
  ASSERT_EQ(two.size(), 3u);
  EXPECT_DOUBLE_EQ(two[1], 95.0);   // the upper one stays
  EXPECT_DOUBLE_EQ(two[0], 107.0);  // the lower one moves down by 7 px
  EXPECT_DOUBLE_EQ(two[2], 200.0);  // far from both: unmoved

  const std::vector<double> crowd = SpreadLabels({279.0, 278.0, 277.0, 30.0}, 12.0, 20.0, 280.0);
  EXPECT_DOUBLE_EQ(crowd[0], 280.0);
  EXPECT_DOUBLE_EQ(crowd[1], 268.0);
  EXPECT_DOUBLE_EQ(crowd[2], 256.0);
  EXPECT_DOUBLE_EQ(crowd[3], 30.0);
  std::vector<double> sorted = crowd;
  std::sort(sorted.begin(), sorted.end());
  for (std::size_t i = 1; i < sorted.size(); ++i) EXPECT_GE(sorted[i] - sorted[i - 1], 12.0);
  EXPECT_DOUBLE_EQ(SpreadLabels({5.0}, 12.0, 20.0, 280.0)[0], 20.0);  // kept inside the frame
  EXPECT_TRUE(SpreadLabels({}, 12.0, 20.0, 280.0).empty());
}

TEST(Chart, PngAndErrors) {
  const std::string png = RenderChartPng(Sample());
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  EXPECT_THROW(RenderChartSvg(Chart{}), std::invalid_argument);
  Chart tiny = Sample();
  tiny.width_px = 200;
  EXPECT_THROW(RenderChartSvg(tiny), std::invalid_argument);
  EXPECT_THROW(WriteChart("/nonexistent-dir/x.svg", Sample()), FileError);
  const eol::testing::TempDir dir;
  WriteChart(dir / "c.png", Sample());
  std::ifstream in(dir / "c.png", std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  EXPECT_EQ(head, png.substr(0, 8));
}

}  // namespace
}  // namespace eol::io
