#include "image/line_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/errors.h"
#include "image/draw.h"

namespace handlabel {
namespace {

std::string TickText(double v) {
  char buf[32];
  const double a = std::abs(v);
  if (v == 0)
    std::snprintf(buf, sizeof(buf), "0");
  else if (a >= 1e5 || a < 1e-3)
    std::snprintf(buf, sizeof(buf), "%.0e", v);
  else
    std::snprintf(buf, sizeof(buf), "%g", v);
  return buf;
}

// Round tick positions covering [lo, hi].
std::vector<double> LinearTicks(double lo, double hi) {
  const double span = hi - lo;
  const double raw = span / 6;
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    if (m * mag >= raw) {
      step = m * mag;
      break;
    }
  }
  std::vector<double> ticks;
  for (double t = std::ceil(lo / step) * step; t <= hi + 1e-9 * span; t += step) {
    ticks.push_back(std::abs(t) < 1e-12 * span ? 0.0 : t);
  }
  return ticks;
}

// Where the data goes: the plot area (pixels) and the axis ranges it shows (y in
// log10 units on a log axis).
struct PlotFrame {
  int left = 70, right = 20, top = 30, bottom = 40;
  int pw = 0, ph = 0;  // plot area width and height
  bool log_y = false;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;

  double Ty(double y) const { return log_y ? std::log10(y) : y; }
  double Px(double x) const { return left + (x - x0) / (x1 - x0) * pw; }
  double Py(double y) const { return top + ph - (Ty(y) - y0) / (y1 - y0) * ph; }
};

bool Plottable(const PlotOptions& o, double x, double y) {
  return std::isfinite(x) && std::isfinite(y) && !(o.log_y && y <= 0);
}

// Axis ranges from the options, else from the data; log axes span whole decades.
PlotFrame MakeFrame(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  PlotFrame f;
  f.pw = o.width - f.left - f.right;
  f.ph = o.height - f.top - f.bottom;
  f.log_y = o.log_y;
  double dx0 = INFINITY, dx1 = -INFINITY, dy0 = INFINITY, dy1 = -INFINITY;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!Plottable(o, s.x[i], s.y[i])) continue;
      dx0 = std::min(dx0, s.x[i]);
      dx1 = std::max(dx1, s.x[i]);
      dy0 = std::min(dy0, f.Ty(s.y[i]));
      dy1 = std::max(dy1, f.Ty(s.y[i]));
    }
  }
  f.x0 = std::isnan(o.x_min) ? (std::isfinite(dx0) ? dx0 : 0.0) : o.x_min;
  f.x1 = std::isnan(o.x_max) ? (std::isfinite(dx1) ? dx1 : 1.0) : o.x_max;
  f.y0 = std::isnan(o.y_min) ? (std::isfinite(dy0) ? dy0 : 0.0) : f.Ty(o.y_min);
  f.y1 = std::isnan(o.y_max) ? (std::isfinite(dy1) ? dy1 : 1.0) : f.Ty(o.y_max);
  if (o.log_y) {
    f.y0 = std::floor(f.y0);
    f.y1 = std::max(std::ceil(f.y1), f.y0 + 1);
  }
  if (!(f.x1 > f.x0)) f.x1 = f.x0 + 1;
  if (!(f.y1 > f.y0)) f.y1 = f.y0 + 1;
  return f;
}

// Grid lines with tick labels, the axes, the title and the axis labels.
void DrawAxes(const PlotFrame& f, const PlotOptions& o, ImageU8* img) {
  const Rgb black = {0, 0, 0}, grid = {225, 225, 225};
  const int left = f.left, top = f.top, pw = f.pw, ph = f.ph;
  for (double t : LinearTicks(f.x0, f.x1)) {
    const double x = f.Px(t);
    DrawLine(img, {x, double(top)}, {x, double(top + ph)}, grid);
    const std::string label = TickText(t);
    DrawText(img, static_cast<int>(x) - 3 * static_cast<int>(label.size()), top + ph + 6,
             label, black);
  }
  std::vector<double> yt;
  if (o.log_y) {
    for (double e = f.y0; e <= f.y1 + 1e-9; e += 1) yt.push_back(std::pow(10.0, e));
  } else {
    yt = LinearTicks(f.y0, f.y1);
  }
  for (double t : yt) {
    const double y = f.Py(t);
    DrawLine(img, {double(left), y}, {double(left + pw), y}, grid);
    const std::string label = TickText(t);
    DrawText(img, left - 6 - kFontAdvance * static_cast<int>(label.size()),
             static_cast<int>(y) - 3, label, black);
  }
  DrawLine(img, {double(left), double(top)}, {double(left), double(top + ph)}, black);
  DrawLine(img, {double(left), double(top + ph)}, {double(left + pw), double(top + ph)},
           black);
  DrawText(img, left, 8, o.title, black, 2);
  DrawText(img, left + pw / 2 - 3 * static_cast<int>(o.x_label.size()), o.height - 14,
           o.x_label, black);
  DrawText(img, 4, top - 12, o.y_label, black);
}

// One polyline per series (broken at unplottable points, clamped to the plot area; a
// single point is a short dash), then its legend entry (top right, one per row).
void DrawSeries(const PlotFrame& f, const PlotOptions& o,
                const std::vector<PlotSeries>& series, ImageU8* img) {
  const Rgb black = {0, 0, 0};
  int legend_y = f.top + 6;
  for (const PlotSeries& s : series) {
    bool have_prev = false;
    Eigen::Vector2d prev(0, 0);
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!Plottable(o, s.x[i], s.y[i])) {
        have_prev = false;
        continue;
      }
      const Eigen::Vector2d p(
          std::clamp(f.Px(s.x[i]), double(f.left), double(f.left + f.pw)),
          std::clamp(f.Py(s.y[i]), double(f.top), double(f.top + f.ph)));
      if (have_prev && s.lines) DrawLine(img, prev, p, s.color, 2);
      if (s.x.size() == 1 && s.lines && s.marker_radius <= 0)
        DrawLine(img, {p.x() - 2, p.y()}, {p.x() + 2, p.y()}, s.color, 2);
      if (s.marker_radius > 0) DrawDisc(img, p, s.marker_radius, s.color);
      prev = p;
      have_prev = true;
    }
    const int lx =
        f.left + f.pw - 8 - kFontAdvance * static_cast<int>(s.name.size()) - 24;
    if (s.lines || s.marker_radius <= 0) {
      DrawLine(img, {double(lx), double(legend_y + 3)},
               {double(lx + 16), double(legend_y + 3)}, s.color, 2);
    } else {
      DrawDisc(img, {lx + 8.0, legend_y + 3.0}, s.marker_radius, s.color);
    }
    DrawText(img, lx + 22, legend_y, s.name, black);
    legend_y += 12;
  }
}

}  // namespace

std::array<uint8_t, 3> PlotColor(int i) {
  static const std::array<std::array<uint8_t, 3>, 10> colors = {{{31, 119, 180},
                                                                 {255, 127, 14},
                                                                 {44, 160, 44},
                                                                 {214, 39, 40},
                                                                 {148, 103, 189},
                                                                 {140, 86, 75},
                                                                 {227, 119, 194},
                                                                 {127, 127, 127},
                                                                 {188, 189, 34},
                                                                 {23, 190, 207}}};
  return colors[((i % 10) + 10) % 10];
}

ImageU8 DrawLinePlot(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  ImageU8 img(o.width, o.height, 3, 255);
  const PlotFrame frame = MakeFrame(series, o);
  DrawAxes(frame, o, &img);
  DrawSeries(frame, o, series, &img);
  return img;
}

ImageU8 DrawBarPlot(const std::vector<PlotSeries>& series, const PlotOptions& options) {
  size_t categories = 0;
  for (const PlotSeries& s : series) categories = std::max(categories, s.y.size());
  PlotOptions o = options;
  o.log_y = false;
  if (std::isnan(o.x_min)) o.x_min = -0.5;
  if (std::isnan(o.x_max)) o.x_max = std::max<double>(categories, 1) - 0.5;
  if (std::isnan(o.y_min)) o.y_min = 0;
  // The frame from the bar tops (x = category index).
  std::vector<PlotSeries> tops;
  for (const PlotSeries& s : series) {
    PlotSeries t = s;
    t.x.clear();
    for (size_t i = 0; i < s.y.size(); ++i) t.x.push_back(double(i));
    tops.push_back(std::move(t));
  }
  ImageU8 img(o.width, o.height, 3, 255);
  const PlotFrame f = MakeFrame(tops, o);
  DrawAxes(f, o, &img);
  const double slot = f.pw / (f.x1 - f.x0);  // pixels per category
  const double bar = 0.8 * slot / std::max<size_t>(series.size(), 1);
  const Rgb black = {0, 0, 0};
  int legend_y = f.top + 6;
  for (size_t k = 0; k < series.size(); ++k) {
    const PlotSeries& s = series[k];
    for (size_t i = 0; i < s.y.size(); ++i) {
      if (!std::isfinite(s.y[i])) continue;
      const double x_left = f.Px(double(i)) - 0.4 * slot + k * bar;
      const double y_top = std::clamp(f.Py(s.y[i]), double(f.top), double(f.top + f.ph));
      const double y_base =
          std::clamp(f.Py(std::max(f.y0, 0.0)), double(f.top), double(f.top + f.ph));
      for (int x = static_cast<int>(std::lround(x_left));
           x < static_cast<int>(std::lround(x_left + bar)); ++x) {
        for (int y = static_cast<int>(std::lround(std::min(y_top, y_base)));
             y <= static_cast<int>(std::lround(std::max(y_top, y_base))); ++y) {
          SetPixel(&img, x, y, s.color);
        }
      }
    }
    const int lx =
        f.left + f.pw - 8 - kFontAdvance * static_cast<int>(s.name.size()) - 24;
    for (int y = legend_y; y < legend_y + 7; ++y)
      for (int x = lx + 4; x < lx + 14; ++x) SetPixel(&img, x, y, s.color);
    DrawText(&img, lx + 22, legend_y, s.name, black);
    legend_y += 12;
  }
  return img;
}

std::vector<int> HistogramCounts(const std::vector<double>& values, double lo, double hi,
                                 int bins) {
  HL_CHECK(bins >= 1 && hi > lo, "bins >= 1 and hi > lo");
  std::vector<int> counts(bins, 0);
  for (double v : values) {
    if (!std::isfinite(v)) continue;
    const int b = static_cast<int>(std::floor((v - lo) / (hi - lo) * bins));
    ++counts[std::clamp(b, 0, bins - 1)];
  }
  return counts;
}

ImageU8 StackHorizontally(const std::vector<ImageU8>& images, int gap) {
  int width = 0, height = 0;
  for (const ImageU8& im : images) {
    width += im.width + (width > 0 ? gap : 0);
    height = std::max(height, im.height);
  }
  ImageU8 out(std::max(width, 1), std::max(height, 1), 3, 255);
  int x0 = 0;
  for (const ImageU8& im : images) {
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        for (int c = 0; c < 3; ++c)
          out.at(x0 + x, y, c) = im.at(x, y, std::min(c, im.channels - 1));
    x0 += im.width + gap;
  }
  return out;
}

ImageU8 StackVertically(const std::vector<ImageU8>& images) {
  int width = 0, height = 0;
  for (const ImageU8& im : images) {
    width = std::max(width, im.width);
    height += im.height;
  }
  ImageU8 out(width, height, 3, 255);
  int y0 = 0;
  for (const ImageU8& im : images) {
    for (int y = 0; y < im.height; ++y)
      for (int x = 0; x < im.width; ++x)
        for (int c = 0; c < 3; ++c)
          out.at(x, y0 + y, c) = im.at(x, y, std::min(c, im.channels - 1));
    y0 += im.height;
  }
  return out;
}

}  // namespace handlabel
