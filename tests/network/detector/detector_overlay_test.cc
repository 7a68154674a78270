#include "network/detector/detector_overlay.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "hand/hand_skeleton.h"

namespace handlabel {
namespace {

Rgb PixelAt(const ImageU8& img, int x, int y) {
  return {img.at(x, y, 0), img.at(x, y, 1), img.at(x, y, 2)};
}

int CountColor(const ImageU8& img, const Rgb& color, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) n += PixelAt(img, x, y) == color;
  return n;
}

// A detected view: one palm box, an unrotated ROI, keypoints spread on a grid, the
// first one sure (confidence 1) and the second one barely (0.05), one unknown.
ViewHandResult DetectedView() {
  ViewHandResult v;
  v.detected = true;
  v.source = "palm";
  v.hand.presence = 0.93;
  PalmDetection palm;
  palm.xmin = 0.25;  // 160 px of 640
  palm.ymin = 0.5;   // 240 px of 480
  palm.width = 0.125;
  palm.height = 0.125;  // 80 x 60 px
  v.palms = {palm};
  v.hand.roi = {0.5, 0.5, 0.25, 1.0 / 3.0, 0.0};  // 160 x 160 px around (320, 240)
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    v.keypoints.uv_px.row(k) << 260 + 30 * (k % 5), 180 + 30 * (k / 5);
    v.keypoints.confidence(k) = 1.0;
  }
  v.keypoints.confidence(1) = 0.05;
  v.keypoints.confidence(20) = 0.0;
  return v;
}

TEST(DetectOverlay, DrawsPalmBoxRoiKeypointsAndCaption) {
  ImageU8 img(640, 480, 3, 0);
  const ViewHandResult view = DetectedView();
  DrawHandDetection(view, &img);
  // Palm box: (159.5, 239.5) to (239.5, 299.5), edges rounded to pixels 160..240 and
  // 240..300, in yellow (perimeter 280 px, some under the ROI and keypoints).
  EXPECT_EQ(PixelAt(img, 200, 240), kPalmBoxColor);  // top edge
  EXPECT_EQ(PixelAt(img, 160, 270), kPalmBoxColor);  // left edge
  EXPECT_GT(CountColor(img, kPalmBoxColor, 150, 230, 250, 310), 200);
  // ROI corners at (239.5, 159.5) and (399.5, 319.5): its top and right edges in cyan
  // (away from keypoints and the palm box).
  EXPECT_GT(CountColor(img, kRoiColor, 380, 150, 420, 340), 150);
  EXPECT_GT(CountColor(img, kRoiColor, 250, 150, 400, 170), 140);
  // Keypoint 0 at (260, 180), confidence 1: a disc of radius 4 in its finger colour
  // (the skeleton leaves it only rightwards and downwards).
  EXPECT_EQ(PixelAt(img, 260, 180), SnapKeypointColor(0));
  EXPECT_EQ(PixelAt(img, 262, 177), SnapKeypointColor(0));  // 3.6 px from its centre
  // Keypoint 1 at (290, 180), confidence 0.05: radius ~1.6, so 2.2 px above-right of it
  // is still the background.
  EXPECT_EQ(PixelAt(img, 290, 180), SnapKeypointColor(1));
  EXPECT_EQ(PixelAt(img, 291, 178), (Rgb{0, 0, 0}));
  // Keypoint 20 (confidence 0, unknown) at (260 + 0, 180 + 120): not drawn.
  EXPECT_NE(PixelAt(img, 260, 300), SnapKeypointColor(20));
  // Caption "PALM P0.93" in white at the top left; no red (that is for no hand).
  EXPECT_GT(CountColor(img, kCaptionColor, 0, 0, 160, 24), 40);
  EXPECT_EQ(CountColor(img, kNoHandColor, 0, 0, 640, 480), 0);
  EXPECT_EQ(DetectionCaption(view), "PALM P0.93");
}

TEST(DetectOverlay, ViewWithoutHandShowsItsReasonInRed) {
  ImageU8 img(640, 480, 3, 0);
  ViewHandResult view = DetectedView();
  view.detected = false;
  view.reason = "low_presence";
  DrawHandDetection(view, &img);
  EXPECT_EQ(DetectionCaption(view), "NONE: LOW_PRESENCE");
  EXPECT_GT(CountColor(img, kNoHandColor, 0, 0, 300, 24), 60);
  // No ROI and no keypoints for a view without a detection; its palm boxes still show.
  EXPECT_EQ(CountColor(img, kRoiColor, 0, 0, 640, 480), 0);
  EXPECT_NE(PixelAt(img, 260, 180), SnapKeypointColor(0));
  EXPECT_EQ(CountColor(img, kPalmBoxColor, 150, 230, 250, 310), 280);
}

TEST(DetectOverlay, RoiCornersFollowTheRotation) {
  // A quarter turn swaps the ROI's width and height in pixels.
  const NormalizedRect roi{0.5, 0.5, 0.25, 0.5, M_PI / 2};  // 160 x 240 px
  const auto c = RoiCornersPx(roi, 640, 480);
  ASSERT_EQ(c.size(), 4u);
  const double xs[] = {c[0].x(), c[1].x(), c[2].x(), c[3].x()};
  const double ys[] = {c[0].y(), c[1].y(), c[2].y(), c[3].y()};
  EXPECT_NEAR(*std::max_element(xs, xs + 4) - *std::min_element(xs, xs + 4), 240, 1e-9);
  EXPECT_NEAR(*std::max_element(ys, ys + 4) - *std::min_element(ys, ys + 4), 160, 1e-9);
  EXPECT_NEAR(0.25 * (xs[0] + xs[1] + xs[2] + xs[3]), 319.5, 1e-9);
}

}  // namespace
}  // namespace handlabel
