#pragma once
// Plots drawn in software on core/image (no plotting library, no Python): axes with
// tick labels in the built-in 5x7 pixel font (image/draw.h), one polyline and/or one
// marker per point for each series, a legend; and grouped bar charts on the same axes.
// Used for training curves (loss.png), PCK curves and the comparison report's pictures
// (scatter plots, per-joint errors, histograms).

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "image/image.h"

namespace handlabel {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // equal length; non-finite points are skipped
  std::array<uint8_t, 3> color = {31, 119, 180};
  bool lines = true;      // join consecutive points
  int marker_radius = 0;  // > 0: a disc of this radius (pixels) at every point
};

struct PlotOptions {
  int width = 800;  // pixels
  int height = 400;
  std::string title, x_label, y_label;
  bool log_y = false;  // logarithmic y axis (non-positive values skipped)
  // Axis limits; NaN = from the data.
  double x_min = std::numeric_limits<double>::quiet_NaN();
  double x_max = std::numeric_limits<double>::quiet_NaN();
  double y_min = std::numeric_limits<double>::quiet_NaN();
  double y_max = std::numeric_limits<double>::quiet_NaN();
};

// RGB image of the plot.
ImageU8 DrawLinePlot(const std::vector<PlotSeries>& series, const PlotOptions& options);

// Grouped bar chart: category i (x = i, ticks at the indices) gets one bar per series,
// side by side, from 0 to series.y[i] (series.x is ignored). The y axis starts at 0
// unless options.y_min says otherwise; log_y is not supported (ignored).
ImageU8 DrawBarPlot(const std::vector<PlotSeries>& series, const PlotOptions& options);

// Counts of `values` in `bins` equal bins over [lo, hi); values outside are clamped
// into the first / last bin, non-finite ones are skipped. bins >= 1, hi > lo.
std::vector<int> HistogramCounts(const std::vector<double>& values, double lo, double hi,
                                 int bins);

// Images one above the other (RGB, same width; narrower ones are padded white).
ImageU8 StackVertically(const std::vector<ImageU8>& images);

// Images side by side (RGB, same height; shorter ones are padded white below), with
// `gap` white pixels between them.
ImageU8 StackHorizontally(const std::vector<ImageU8>& images, int gap = 0);

// A distinct colour for series i (a 10-colour cycle).
std::array<uint8_t, 3> PlotColor(int i);

}  // namespace handlabel
