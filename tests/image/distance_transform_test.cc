#include "image/distance_transform.h"

#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_util.h"

namespace handlabel {
namespace {

// Brute force: nearest pixel with the wanted value.
DistanceImage BruteForce(const MaskImage& mask, bool target_nonzero) {
  DistanceImage d(mask.rows(), mask.cols());
  for (int r = 0; r < mask.rows(); ++r) {
    for (int c = 0; c < mask.cols(); ++c) {
      double best = std::numeric_limits<double>::infinity();
      for (int r2 = 0; r2 < mask.rows(); ++r2) {
        for (int c2 = 0; c2 < mask.cols(); ++c2) {
          if ((mask(r2, c2) != 0) != target_nonzero) continue;
          best = std::min(best, std::hypot(double(r - r2), double(c - c2)));
        }
      }
      d(r, c) = best;
    }
  }
  return d;
}

TEST(DistanceTransformTest, MatchesBruteForceOnRandomMasks) {
  for (int trial = 0; trial < 5; ++trial) {
    MaskImage mask(17, 23);
    const double density = testing::Uniform(0.02, 0.6);
    for (int i = 0; i < mask.size(); ++i)
      mask.data()[i] = testing::Uniform(0, 1) < density;
    EXPECT_THAT(Eigen::MatrixXd(DistanceToMask(mask)),
                testing::MatrixNear(Eigen::MatrixXd(BruteForce(mask, true)), 1e-12));
    EXPECT_THAT(Eigen::MatrixXd(DistanceToOutside(mask)),
                testing::MatrixNear(Eigen::MatrixXd(BruteForce(mask, false)), 1e-12));
  }
}

TEST(DistanceTransformTest, SinglePixelAndEmpty) {
  MaskImage mask = MaskImage::Zero(5, 7);
  EXPECT_TRUE(std::isinf(DistanceToMask(mask)(2, 2)));
  mask(1, 2) = 1;
  const DistanceImage d = DistanceToMask(mask);
  EXPECT_DOUBLE_EQ(d(1, 2), 0.0);
  EXPECT_DOUBLE_EQ(d(4, 6), 5.0);  // (3, 4) away
}

TEST(DistanceTransformTest, WindowMatchesTheWholeImageWhereTheNearestPixelIsInside) {
  for (int trial = 0; trial < 5; ++trial) {
    MaskImage mask(19, 25), also = MaskImage::Zero(19, 25);
    const double density = testing::Uniform(0.02, 0.3);
    for (int i = 0; i < mask.size(); ++i) {
      mask.data()[i] = testing::Uniform(0, 1) < density;
      also.data()[i] = testing::Uniform(0, 1) < 0.05 ? 255 : 0;
    }
    MaskImage joined = mask;
    for (int i = 0; i < mask.size(); ++i) joined.data()[i] |= also.data()[i] != 0;
    const DistanceImage full = DistanceToMask(joined);
    const PixelWindow window{4, 3, 15, 11};
    const DistanceImage part = DistanceToMaskInWindow(mask, window, &also);
    ASSERT_EQ(part.rows(), 11);
    ASSERT_EQ(part.cols(), 15);
    int compared = 0;
    for (int r = 0; r < part.rows(); ++r) {
      for (int c = 0; c < part.cols(); ++c) {
        const int to_edge =
            std::min({r + 1, c + 1, int(part.rows()) - r, int(part.cols()) - c});
        // Never below the whole image's; equal where the window cannot miss a nearer
        // pixel.
        EXPECT_GE(part(r, c), full(r + 3, c + 4) - 1e-12);
        if (part(r, c) <= to_edge) {
          EXPECT_NEAR(part(r, c), full(r + 3, c + 4), 1e-12);
          ++compared;
        }
      }
    }
    EXPECT_GT(compared, 50);
  }
}

}  // namespace
}  // namespace handlabel
