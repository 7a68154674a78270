#include "core/line_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>

namespace handlabel {
namespace {

// 5x7 glyphs, one byte per row, bit 4 = leftmost column.
const std::map<char, std::array<uint8_t, 7>>& Font() {
  static const std::map<char, std::array<uint8_t, 7>> font = {
      {'0', {0x0E, 0x11, 0x13, 0x15, 0x19, 0x11, 0x0E}},
      {'1', {0x04, 0x0C, 0x04, 0x04, 0x04, 0x04, 0x0E}},
      {'2', {0x0E, 0x11, 0x01, 0x02, 0x04, 0x08, 0x1F}},
      {'3', {0x1F, 0x02, 0x04, 0x02, 0x01, 0x11, 0x0E}},
      {'4', {0x02, 0x06, 0x0A, 0x12, 0x1F, 0x02, 0x02}},
      {'5', {0x1F, 0x10, 0x1E, 0x01, 0x01, 0x11, 0x0E}},
      {'6', {0x06, 0x08, 0x10, 0x1E, 0x11, 0x11, 0x0E}},
      {'7', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x08, 0x08}},
      {'8', {0x0E, 0x11, 0x11, 0x0E, 0x11, 0x11, 0x0E}},
      {'9', {0x0E, 0x11, 0x11, 0x0F, 0x01, 0x02, 0x0C}},
      {'A', {0x0E, 0x11, 0x11, 0x11, 0x1F, 0x11, 0x11}},
      {'B', {0x1E, 0x11, 0x11, 0x1E, 0x11, 0x11, 0x1E}},
      {'C', {0x0E, 0x11, 0x10, 0x10, 0x10, 0x11, 0x0E}},
      {'D', {0x1C, 0x12, 0x11, 0x11, 0x11, 0x12, 0x1C}},
      {'E', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x1F}},
      {'F', {0x1F, 0x10, 0x10, 0x1E, 0x10, 0x10, 0x10}},
      {'G', {0x0E, 0x11, 0x10, 0x17, 0x11, 0x11, 0x0F}},
      {'H', {0x11, 0x11, 0x11, 0x1F, 0x11, 0x11, 0x11}},
      {'I', {0x0E, 0x04, 0x04, 0x04, 0x04, 0x04, 0x0E}},
      {'J', {0x07, 0x02, 0x02, 0x02, 0x02, 0x12, 0x0C}},
      {'K', {0x11, 0x12, 0x14, 0x18, 0x14, 0x12, 0x11}},
      {'L', {0x10, 0x10, 0x10, 0x10, 0x10, 0x10, 0x1F}},
      {'M', {0x11, 0x1B, 0x15, 0x15, 0x11, 0x11, 0x11}},
      {'N', {0x11, 0x11, 0x19, 0x15, 0x13, 0x11, 0x11}},
      {'O', {0x0E, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
      {'P', {0x1E, 0x11, 0x11, 0x1E, 0x10, 0x10, 0x10}},
      {'Q', {0x0E, 0x11, 0x11, 0x11, 0x15, 0x12, 0x0D}},
      {'R', {0x1E, 0x11, 0x11, 0x1E, 0x14, 0x12, 0x11}},
      {'S', {0x0F, 0x10, 0x10, 0x0E, 0x01, 0x01, 0x1E}},
      {'T', {0x1F, 0x04, 0x04, 0x04, 0x04, 0x04, 0x04}},
      {'U', {0x11, 0x11, 0x11, 0x11, 0x11, 0x11, 0x0E}},
      {'V', {0x11, 0x11, 0x11, 0x11, 0x11, 0x0A, 0x04}},
      {'W', {0x11, 0x11, 0x11, 0x15, 0x15, 0x15, 0x0A}},
      {'X', {0x11, 0x11, 0x0A, 0x04, 0x0A, 0x11, 0x11}},
      {'Y', {0x11, 0x11, 0x11, 0x0A, 0x04, 0x04, 0x04}},
      {'Z', {0x1F, 0x01, 0x02, 0x04, 0x08, 0x10, 0x1F}},
      {'.', {0x00, 0x00, 0x00, 0x00, 0x00, 0x0C, 0x0C}},
      {',', {0x00, 0x00, 0x00, 0x00, 0x0C, 0x04, 0x08}},
      {'-', {0x00, 0x00, 0x00, 0x1F, 0x00, 0x00, 0x00}},
      {'+', {0x00, 0x04, 0x04, 0x1F, 0x04, 0x04, 0x00}},
      {':', {0x00, 0x0C, 0x0C, 0x00, 0x0C, 0x0C, 0x00}},
      {'/', {0x00, 0x01, 0x02, 0x04, 0x08, 0x10, 0x00}},
      {'(', {0x02, 0x04, 0x08, 0x08, 0x08, 0x04, 0x02}},
      {')', {0x08, 0x04, 0x02, 0x02, 0x02, 0x04, 0x08}},
      {'%', {0x18, 0x19, 0x02, 0x04, 0x08, 0x13, 0x03}},
      {'_', {0x00, 0x00, 0x00, 0x00, 0x00, 0x00, 0x1F}},
      {'=', {0x00, 0x00, 0x1F, 0x00, 0x1F, 0x00, 0x00}},
  };
  return font;
}

constexpr int kGlyphAdvance = 6;

void SetPixel(ImageU8* img, int x, int y, const std::array<uint8_t, 3>& c) {
  if (!img->Contains(x, y)) return;
  for (int ch = 0; ch < 3; ++ch) img->at(x, y, ch) = c[ch];
}

void DrawLine(ImageU8* img, double x0, double y0, double x1, double y1,
              const std::array<uint8_t, 3>& c, int thickness = 1) {
  const int steps =
      static_cast<int>(std::ceil(std::max(std::abs(x1 - x0), std::abs(y1 - y0))));
  for (int i = 0; i <= steps; ++i) {
    const double t = steps == 0 ? 0.0 : static_cast<double>(i) / steps;
    const int x = static_cast<int>(std::lround(x0 + t * (x1 - x0)));
    const int y = static_cast<int>(std::lround(y0 + t * (y1 - y0)));
    for (int dy = 0; dy < thickness; ++dy)
      for (int dx = 0; dx < thickness; ++dx) SetPixel(img, x + dx, y + dy, c);
  }
}

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

void DrawText(ImageU8* image, int x, int y, const std::string& text,
              const std::array<uint8_t, 3>& color, int scale) {
  for (char raw : text) {
    const char ch = static_cast<char>(std::toupper(static_cast<unsigned char>(raw)));
    auto it = Font().find(ch);
    if (it != Font().end()) {
      for (int r = 0; r < 7; ++r) {
        for (int col = 0; col < 5; ++col) {
          if (!(it->second[r] & (0x10 >> col))) continue;
          for (int dy = 0; dy < scale; ++dy)
            for (int dx = 0; dx < scale; ++dx)
              SetPixel(image, x + col * scale + dx, y + r * scale + dy, color);
        }
      }
    }
    x += kGlyphAdvance * scale;
  }
}

ImageU8 DrawLinePlot(const std::vector<PlotSeries>& series, const PlotOptions& o) {
  ImageU8 img(o.width, o.height, 3, 255);
  const std::array<uint8_t, 3> black = {0, 0, 0}, grid = {225, 225, 225};
  const int left = 70, right = 20, top = 30, bottom = 40;
  const int pw = o.width - left - right, ph = o.height - top - bottom;
  auto ty = [&](double y) { return o.log_y ? std::log10(y) : y; };
  double x0 = o.x_min, x1 = o.x_max, y0 = std::nan(""), y1 = std::nan("");
  double dx0 = INFINITY, dx1 = -INFINITY, dy0 = INFINITY, dy1 = -INFINITY;
  for (const PlotSeries& s : series) {
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (o.log_y && s.y[i] <= 0))
        continue;
      dx0 = std::min(dx0, s.x[i]);
      dx1 = std::max(dx1, s.x[i]);
      dy0 = std::min(dy0, ty(s.y[i]));
      dy1 = std::max(dy1, ty(s.y[i]));
    }
  }
  if (std::isnan(x0)) x0 = std::isfinite(dx0) ? dx0 : 0.0;
  if (std::isnan(x1)) x1 = std::isfinite(dx1) ? dx1 : 1.0;
  y0 = std::isnan(o.y_min) ? (std::isfinite(dy0) ? dy0 : 0.0) : ty(o.y_min);
  y1 = std::isnan(o.y_max) ? (std::isfinite(dy1) ? dy1 : 1.0) : ty(o.y_max);
  if (o.log_y) {
    y0 = std::floor(y0);
    y1 = std::max(std::ceil(y1), y0 + 1);
  }
  if (!(x1 > x0)) x1 = x0 + 1;
  if (!(y1 > y0)) y1 = y0 + 1;
  auto px = [&](double x) { return left + (x - x0) / (x1 - x0) * pw; };
  auto py = [&](double y) { return top + ph - (ty(y) - y0) / (y1 - y0) * ph; };

  // Grid and tick labels.
  for (double t : LinearTicks(x0, x1)) {
    const double x = px(t);
    DrawLine(&img, x, top, x, top + ph, grid);
    const std::string label = TickText(t);
    DrawText(&img, static_cast<int>(x) - 3 * static_cast<int>(label.size()), top + ph + 6,
             label, black);
  }
  std::vector<double> yt;
  if (o.log_y) {
    for (double e = y0; e <= y1 + 1e-9; e += 1) yt.push_back(std::pow(10.0, e));
  } else {
    yt = LinearTicks(y0, y1);
  }
  for (double t : yt) {
    const double y = py(t);
    DrawLine(&img, left, y, left + pw, y, grid);
    const std::string label = TickText(t);
    DrawText(&img, left - 6 - kGlyphAdvance * static_cast<int>(label.size()),
             static_cast<int>(y) - 3, label, black);
  }
  DrawLine(&img, left, top, left, top + ph, black);
  DrawLine(&img, left, top + ph, left + pw, top + ph, black);
  DrawText(&img, left, 8, o.title, black, 2);
  DrawText(&img, left + pw / 2 - 3 * static_cast<int>(o.x_label.size()), o.height - 14,
           o.x_label, black);
  DrawText(&img, 4, top - 12, o.y_label, black);

  // Series, then the legend (top right).
  int legend_y = top + 6;
  for (const PlotSeries& s : series) {
    bool have_prev = false;
    double prev_x = 0, prev_y = 0;
    for (size_t i = 0; i < s.x.size() && i < s.y.size(); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i]) || (o.log_y && s.y[i] <= 0)) {
        have_prev = false;
        continue;
      }
      const double x = std::clamp(px(s.x[i]), double(left), double(left + pw));
      const double y = std::clamp(py(s.y[i]), double(top), double(top + ph));
      if (have_prev) DrawLine(&img, prev_x, prev_y, x, y, s.color, 2);
      if (s.x.size() == 1) DrawLine(&img, x - 2, y, x + 2, y, s.color, 2);
      prev_x = x;
      prev_y = y;
      have_prev = true;
    }
    const int lx = left + pw - 8 - kGlyphAdvance * static_cast<int>(s.name.size()) - 24;
    DrawLine(&img, lx, legend_y + 3, lx + 16, legend_y + 3, s.color, 2);
    DrawText(&img, lx + 22, legend_y, s.name, black);
    legend_y += 12;
  }
  return img;
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
