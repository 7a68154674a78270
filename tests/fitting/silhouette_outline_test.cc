#include "fitting/silhouette_outline.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace handlabel {
namespace {

// A disk of radius 20 px centred at (50.3, 40.6): outline points lie on the circle to
// within the pixel grid and their normals point radially outwards.
TEST(SilhouetteOutlineTest, DiskOutlineAndNormals) {
  const Eigen::Vector2d centre(50.3, 40.6);
  const double radius = 20.0;
  MaskImage mask = MaskImage::Zero(90, 110);
  for (int y = 0; y < 90; ++y) {
    for (int x = 0; x < 110; ++x) {
      mask(y, x) = (Eigen::Vector2d(x, y) - centre).norm() <= radius;
    }
  }
  const MaskOutline outline = SampleMaskOutline(mask, 40);
  ASSERT_GE(outline.points.size(), 30u);
  ASSERT_LE(outline.points.size(), 41u);
  for (size_t i = 0; i < outline.points.size(); ++i) {
    const Eigen::Vector2d radial = (outline.points[i] - centre).normalized();
    EXPECT_NEAR((outline.points[i] - centre).norm(), radius, 0.8);
    EXPECT_GT(outline.normals[i].dot(radial), std::cos(12.0 * M_PI / 180.0));
  }
}

// Projected points on a circle 3 px inside a disk mask's outline; every fifth outline
// sample is matched to the centre instead (where the fit or the mask is locally off):
// the margin is the median gap, 3 px.
TEST(SilhouetteOutlineTest, MaskMarginIsTheMedianGap) {
  const Eigen::Vector2d centre(50.3, 40.6);
  MaskImage mask = MaskImage::Zero(90, 110);
  for (int y = 0; y < 90; ++y) {
    for (int x = 0; x < 110; ++x)
      mask(y, x) = (Eigen::Vector2d(x, y) - centre).norm() <= 20;
  }
  const MaskOutline outline = SampleMaskOutline(mask, 60);
  std::vector<Eigen::Vector2d> projected;
  for (int i = 0; i < 360; ++i) {
    const double a = i * M_PI / 180;
    projected.push_back(centre + 17.0 * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  std::vector<int> match =
      MatchOutlineToPoints(outline, projected, std::vector<char>(projected.size(), 1));
  projected.push_back(centre);
  for (size_t s = 0; s < match.size(); s += 5) match[s] = 360;
  EXPECT_NEAR(EstimateMaskMargin(outline, match, projected), 3.0, 0.6);
  EXPECT_EQ(EstimateMaskMargin(outline, std::vector<int>(match.size(), -1), projected),
            0);
  const std::vector<Eigen::Vector2d> shifted = ShiftedOutline(outline, 3.0);
  ASSERT_EQ(shifted.size(), outline.points.size());
  for (size_t s = 0; s < shifted.size(); ++s) {
    EXPECT_NEAR((shifted[s] - centre).norm(), 17.0, 0.8);
  }
}

TEST(SilhouetteOutlineTest, MatchesNearestValidPoint) {
  MaskOutline outline;
  outline.points = {{0, 0}, {10, 0}};
  outline.normals = {{1, 0}, {1, 0}};
  const std::vector<Eigen::Vector2d> projected = {{1, 0}, {9, 0}, {10, 0.5}};
  const std::vector<int> match = MatchOutlineToPoints(outline, projected, {1, 1, 0});
  EXPECT_EQ(match[0], 0);
  EXPECT_EQ(match[1], 1);  // the nearer point 2 is not valid
  EXPECT_EQ(MatchOutlineToPoints(outline, projected, {0, 0, 0})[0], -1);
}

// A square hand mask whose right side touches an object: the outline keeps the other
// three sides and drops the pixels within the occluder reach of the object.
TEST(SilhouetteOutlineTest, NoOutlineNextToAnOccluder) {
  constexpr int kReach = 2;  // SampleMaskOutline's default
  MaskImage hand = MaskImage::Zero(40, 40);
  hand.block(10, 10, 20, 20).setConstant(255);  // columns 10..29
  MaskImage object = MaskImage::Zero(40, 40);
  object.block(5, 30, 30, 6).setConstant(255);  // columns 30..35, right of the hand
  const MaskOutline all = SampleMaskOutline(hand, 1000);
  const MaskOutline visible = SampleMaskOutline(hand, 1000, &object);
  // Kept boundary pixels reach column 29 - kReach; points sit at most half a pixel
  // further out.
  const double last_kept = 29 - kReach + 0.5;
  int right_all = 0, right_visible = 0;
  for (const Eigen::Vector2d& p : all.points) right_all += p.x() > last_kept;
  for (const Eigen::Vector2d& p : visible.points) right_visible += p.x() > last_kept;
  EXPECT_GT(right_all, 20);
  EXPECT_EQ(right_visible, 0);
  EXPECT_GE(visible.points.size(), 50u);  // the three free sides stay
  // The mesh -> mask distance counts the object as "may be hand" (the fitter's
  // DistanceToMaskInWindow with the occluder as `also`).
  const DistanceImage joined = DistanceToMaskInWindow(hand, {0, 0, 40, 40}, &object);
  EXPECT_EQ(joined(20, 33), 0.0);
  EXPECT_EQ(joined(20, 20), 0.0);
  EXPECT_GT(joined(2, 2), 0.0);
}

// A wider reach drops more of the outline: the pixels of the top and bottom sides
// within reach of the object's columns go too.
TEST(SilhouetteOutlineTest, OccluderReachIsTheGapThatStillCounts) {
  MaskImage hand = MaskImage::Zero(40, 40);
  hand.block(10, 10, 20, 20).setConstant(255);  // columns 10..29
  MaskImage object = MaskImage::Zero(40, 40);
  object.block(5, 33, 30, 4).setConstant(255);  // columns 33..36: a 3-pixel gap
  auto rightmost = [](const MaskOutline& outline) {
    double x = 0;
    for (const Eigen::Vector2d& p : outline.points) x = std::max(x, p.x());
    return x;
  };
  // Reach 2 does not bridge the gap: the right side stays an outline (x = 29.5).
  EXPECT_NEAR(rightmost(SampleMaskOutline(hand, 1000, &object, 2)), 29.5, 1e-9);
  // Reach 4 does: boundary pixels from column 33 - 4 = 29 on are dropped.
  EXPECT_LE(rightmost(SampleMaskOutline(hand, 1000, &object, 4)), 28.5 + 1e-9);
  EXPECT_LE(rightmost(SampleMaskOutline(hand, 1000, &object, 6)), 26.5 + 1e-9);
}

}  // namespace
}  // namespace handlabel
