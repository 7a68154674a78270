#pragma once
// Pixel-wise comparison of two images of the same size, for tests of image I/O.

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <utility>

#include "image/image.h"

namespace handlabel::testing {

// Mean and largest absolute channel difference; a size mismatch fails the test and
// reports the largest possible difference.
inline std::pair<double, int> ImageDifference(const ImageU8& a, const ImageU8& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  EXPECT_EQ(a.channels, b.channels);
  if (a.data.size() != b.data.size() || a.data.empty()) return {1e9, 255};
  double sum = 0;
  int worst = 0;
  for (size_t i = 0; i < a.data.size(); ++i) {
    const int d = std::abs(int(a.data[i]) - int(b.data[i]));
    sum += d;
    worst = std::max(worst, d);
  }
  return {sum / a.data.size(), worst};
}

}  // namespace handlabel::testing
