#include "image/gaussian_blur.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "tests/test_util.h"

namespace handlabel {
namespace {

// A direct 2D convolution with the same truncated, normalised kernel and repeated
// edges, in double precision: a second implementation to compare with.
double DirectBlur(const std::vector<double>& img, int w, int h, int x, int y,
                  double sigma) {
  const int r = std::max(1, static_cast<int>(std::ceil(2.5 * sigma)));
  double total = 0, sum = 0;
  for (int dy = -r; dy <= r; ++dy) {
    for (int dx = -r; dx <= r; ++dx) {
      const double k = std::exp(-0.5 * (dx * dx + dy * dy) / (sigma * sigma));
      const int xx = std::clamp(x + dx, 0, w - 1), yy = std::clamp(y + dy, 0, h - 1);
      sum += k * img[yy * w + xx];
      total += k;
    }
  }
  return sum / total;
}

TEST(GaussianBlur, MatchesADirectConvolutionInBothLayouts) {
  const int w = 13, h = 9, channels = 3;
  const double sigma = 1.3;
  std::vector<std::vector<double>> planes(channels, std::vector<double>(w * h));
  for (auto& plane : planes)
    for (double& v : plane) v = testing::Uniform(0, 255);
  std::vector<float> interleaved(w * h * channels), planar(w * h * channels);
  for (int c = 0; c < channels; ++c)
    for (int i = 0; i < w * h; ++i) {
      interleaved[i * channels + c] = static_cast<float>(planes[c][i]);
      planar[c * w * h + i] = static_cast<float>(planes[c][i]);
    }
  GaussianBlurInPlace(sigma, FloatImageLayout::Interleaved(w, h, channels),
                      interleaved.data());
  GaussianBlurInPlace(sigma, FloatImageLayout::Planar(w, h, channels), planar.data());
  for (int c = 0; c < channels; ++c)
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const double expected = DirectBlur(planes[c], w, h, x, y, sigma);
        // float sums of 255-level values: about 1e-5 relative
        EXPECT_NEAR(interleaved[(y * w + x) * channels + c], expected, 2e-3);
        EXPECT_EQ(planar[c * w * h + y * w + x], interleaved[(y * w + x) * channels + c]);
      }
}

TEST(GaussianBlur, ZeroSigmaLeavesTheImage) {
  std::vector<float> img = {1, 2, 3, 4, 5, 6};
  GaussianBlurInPlace(0.0, FloatImageLayout::Planar(3, 2, 1), img.data());
  EXPECT_EQ(img, (std::vector<float>{1, 2, 3, 4, 5, 6}));
}

}  // namespace
}  // namespace handlabel
