#include "core/distance_transform.h"

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

}  // namespace
}  // namespace handlabel
