#pragma once
// Line plots drawn in software on core/image (no plotting library, no Python): axes with
// tick labels in the built-in 5x7 pixel font (core/draw.h), one polyline per series, a
// legend. Used for training curves (loss.png) and PCK curves.

#include <array>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "core/image.h"

namespace handlabel {

struct PlotSeries {
  std::string name;
  std::vector<double> x, y;  // equal length; non-finite points are skipped
  std::array<uint8_t, 3> color = {31, 119, 180};
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

// Images one above the other (RGB, same width; narrower ones are padded white).
ImageU8 StackVertically(const std::vector<ImageU8>& images);

// A distinct colour for series i (a 10-colour cycle).
std::array<uint8_t, 3> PlotColor(int i);

}  // namespace handlabel
