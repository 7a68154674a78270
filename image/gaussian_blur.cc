#include "image/gaussian_blur.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace handlabel {

FloatImageLayout FloatImageLayout::Interleaved(int width, int height, int channels) {
  return {width,
          height,
          channels,
          static_cast<size_t>(channels),
          static_cast<size_t>(width) * channels,
          1};
}

FloatImageLayout FloatImageLayout::Planar(int width, int height, int channels) {
  return {width,
          height,
          channels,
          1,
          static_cast<size_t>(width),
          static_cast<size_t>(width) * height};
}

void GaussianBlurInPlace(double sigma, const FloatImageLayout& l, float* data) {
  if (!(sigma > 0)) return;
  const int r = std::max(1, static_cast<int>(std::ceil(2.5 * sigma)));
  std::vector<float> kernel(2 * r + 1);
  float total = 0;
  for (int d = -r; d <= r; ++d) {
    kernel[d + r] = std::exp(static_cast<float>(-0.5 * d * d / (sigma * sigma)));
    total += kernel[d + r];
  }
  for (float& k : kernel) k /= total;
  const size_t n = static_cast<size_t>(l.width) * l.height * l.channels;
  std::vector<float> a(data, data + n), b(n);
  auto at = [&](int x, int y, int c) {
    return x * l.x_stride + y * l.y_stride + c * l.channel_stride;
  };
  for (int dir = 0; dir < 2; ++dir) {
    for (int y = 0; y < l.height; ++y) {
      for (int x = 0; x < l.width; ++x) {
        for (int c = 0; c < l.channels; ++c) {
          float sum = 0;
          for (int d = -r; d <= r; ++d) {
            const int xx = dir == 0 ? std::clamp(x + d, 0, l.width - 1) : x;
            const int yy = dir == 1 ? std::clamp(y + d, 0, l.height - 1) : y;
            sum += kernel[d + r] * a[at(xx, yy, c)];
          }
          b[at(x, y, c)] = sum;
        }
      }
    }
    a.swap(b);
  }
  std::copy(a.begin(), a.end(), data);
}

}  // namespace handlabel
