// Plots are exact functions of their inputs: the tests read pixels where the geometry
// of the plot frame (70 px left margin, 20 right, 30 top, 40 bottom) puts them.

#include <gtest/gtest.h>

#include <cmath>

#include "image/line_plot.h"

namespace handlabel {
namespace {

bool Is(const ImageU8& image, int x, int y, const std::array<uint8_t, 3>& color) {
  return image.at(x, y, 0) == color[0] && image.at(x, y, 1) == color[1] &&
         image.at(x, y, 2) == color[2];
}

PlotOptions Frame400x300() {
  PlotOptions o;
  o.width = 400;   // plot area x 70 .. 380
  o.height = 300;  // plot area y 30 .. 260
  return o;
}

TEST(BarPlot, BarHeightsFollowTheValues) {
  PlotOptions o = Frame400x300();
  o.y_max = 2;  // y = 2 at row 30, 1 at row 145, 0 at row 260
  const std::array<uint8_t, 3> red = {200, 0, 0};
  const ImageU8 img = DrawBarPlot({{"s", {}, {1.0, 2.0}, red}}, o);
  // Two categories over x in [-0.5, 1.5]: centres at columns 147.5 and 302.5.
  EXPECT_TRUE(Is(img, 147, 200, red));  // below 1
  EXPECT_TRUE(Is(img, 147, 150, red));
  EXPECT_FALSE(Is(img, 147, 135, red));  // above 1
  EXPECT_TRUE(Is(img, 302, 40, red));    // the bar of 2 reaches the top
  EXPECT_FALSE(Is(img, 225, 200, red));  // between the bars
}

TEST(BarPlot, SeriesSitSideBySide) {
  PlotOptions o = Frame400x300();
  o.y_max = 1;
  const std::array<uint8_t, 3> a = {10, 20, 30}, b = {40, 50, 60};
  const ImageU8 img = DrawBarPlot({{"a", {}, {1.0}, a}, {"b", {}, {1.0}, b}}, o);
  // One category over [-0.5, 0.5] (310 px): bars of 124 px from column 101 and 225.
  EXPECT_TRUE(Is(img, 150, 200, a));
  EXPECT_TRUE(Is(img, 280, 200, b));
}

TEST(ScatterPlot, MarkersWithoutLines) {
  PlotOptions o = Frame400x300();
  o.x_min = 0;
  o.x_max = 1;
  o.y_min = 0;
  o.y_max = 1;
  PlotSeries s{"p", {0.0, 1.0}, {0.0, 1.0}, {0, 0, 255}};
  s.lines = false;
  s.marker_radius = 3;
  const ImageU8 img = DrawLinePlot({s}, o);
  EXPECT_TRUE(Is(img, 72, 258, s.color));    // near (0, 0), clamped into the area
  EXPECT_TRUE(Is(img, 378, 32, s.color));    // near (1, 1)
  EXPECT_FALSE(Is(img, 225, 145, s.color));  // no line between them
  s.lines = true;
  EXPECT_TRUE(Is(DrawLinePlot({s}, o), 225, 145, s.color));
}

TEST(Histogram, CountsClampAndSkipNonFinite) {
  const std::vector<int> counts =
      HistogramCounts({0.1, 0.5, 0.99, -1.0, 5.0, std::nan("")}, 0.0, 1.0, 2);
  EXPECT_EQ(counts, (std::vector<int>{2, 3}));
}

TEST(Stack, HorizontallyWithAGap) {
  const ImageU8 a(3, 2, 3, 10), b(2, 4, 3, 20);
  const ImageU8 s = StackHorizontally({a, b}, 1);
  EXPECT_EQ(s.width, 6);
  EXPECT_EQ(s.height, 4);
  EXPECT_EQ(s.at(2, 1, 0), 10);
  EXPECT_EQ(s.at(3, 1, 0), 255);  // the gap
  EXPECT_EQ(s.at(4, 3, 0), 20);
  EXPECT_EQ(s.at(0, 3, 0), 255);  // below the shorter image
}

}  // namespace
}  // namespace handlabel
