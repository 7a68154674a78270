#include "capture/synth_detections.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"

namespace handlabel {
namespace {

// A 200 x 100 view: visible hand pixels in columns 20..79; an object covers columns
// 80..179. Keypoint 0 is visible at (50, 50); keypoint 1 is behind the object 20 px
// right of the last hand pixel (100, 50); keypoint 2 is self-occluded at (60, 50);
// the others are out of frame.
SynthView ViewWithAnObject() {
  SynthView view;
  view.rgb = ImageU8(200, 100, 3);
  view.hand_mask = ImageU8(200, 100, 1);
  for (int y = 30; y < 70; ++y) {
    for (int x = 20; x < 80; ++x) view.hand_mask.at(x, y) = 255;
  }
  view.keypoints.setConstant(-10.0);
  view.visibility.fill(kOutOfFrame);
  view.keypoints.row(0) << 50, 50;
  view.visibility[0] = kVisible;
  view.keypoints.row(1) << 99, 50;
  view.visibility[1] = kOccluded;
  view.behind_object[1] = true;
  view.keypoints.row(2) << 60, 50;
  view.visibility[2] = kOccluded;
  return view;
}

DetectionNoiseOptions NoOutliersNoDropouts() {
  DetectionNoiseOptions o;
  o.keypoint_sigma_px = 2.0;
  o.outlier_rate = 0;
  o.dropout_rate = 0;
  o.occluded_dropout_rate = 0;
  o.mask_blobs = 0;
  o.mask_morph_radius = 0;
  return o;
}

TEST(SynthDetectionsTest, DepthBehindAnObjectIsTheDistanceToTheVisibleHand) {
  SynthView view = ViewWithAnObject();
  const auto depth = DepthBehindObjects(view, 60.0);
  EXPECT_NEAR(depth[1], 20.0, 1e-9);  // column 99 vs the last hand column 79
  EXPECT_EQ(depth[0], 0.0);           // visible
  EXPECT_EQ(depth[2], 0.0);           // hidden by the hand itself, not an object
  EXPECT_NEAR(DepthBehindObjects(view, 15.0)[1], 15.0, 1e-9);  // capped
  view.hand_mask = ImageU8(200, 100, 1);  // no visible hand pixel: the cap
  EXPECT_NEAR(DepthBehindObjects(view, 60.0)[1], 60.0, 1e-9);
}

// Over many draws: a visible keypoint's error has sigma 2 px, a self-occluded one 4 px,
// and one 20 px behind an object 2 * 2 + 0.25 * 20 = 9 px, with confidence at most
// 0.6 / (1 + 20 / 30) = 0.36 and on average 0.4 / (5 / 3) = 0.24.
TEST(SynthDetectionsTest, KeypointsBehindAnObjectGetNoiseAndConfidenceByDepth) {
  const SynthView view = ViewWithAnObject();
  const DetectionNoiseOptions o = NoOutliersNoDropouts();
  std::mt19937_64 rng(5);
  constexpr int kDraws = 3000;
  double sq[3] = {0, 0, 0}, conf_sum[3] = {0, 0, 0}, conf_max[3] = {0, 0, 0};
  for (int i = 0; i < kDraws; ++i) {
    const ViewDetections det = SimulateDetections(view, o, rng);
    for (int k = 0; k < 3; ++k) {
      sq[k] += (det.keypoints.uv_px.row(k) - view.keypoints.row(k)).squaredNorm();
      conf_sum[k] += det.keypoints.confidence[k];
      conf_max[k] = std::max(conf_max[k], det.keypoints.confidence[k]);
    }
    EXPECT_EQ(det.keypoints.confidence[3], 0.0);  // out of frame: dropped
  }
  auto sigma = [&](int k) { return std::sqrt(sq[k] / (2.0 * kDraws)); };
  EXPECT_NEAR(sigma(0), 2.0, 0.1);
  EXPECT_NEAR(sigma(2), 4.0, 0.2);
  EXPECT_NEAR(sigma(1), 9.0, 0.4);
  EXPECT_NEAR(conf_sum[0] / kDraws, 0.8, 0.02);
  EXPECT_NEAR(conf_sum[2] / kDraws, 0.4, 0.02);
  EXPECT_NEAR(conf_sum[1] / kDraws, 0.24, 0.01);
  EXPECT_LE(conf_max[1], 0.36 + 1e-9);
  EXPECT_GT(conf_max[1], 0.35);
}

// The same draws without objects in the view give the same detections: the rule only
// touches keypoints behind objects.
TEST(SynthDetectionsTest, ViewsWithoutObjectsAreUnchangedByTheObjectRule) {
  SynthView view = ViewWithAnObject();
  view.behind_object.fill(false);
  DetectionNoiseOptions plain = NoOutliersNoDropouts(), strong = plain;
  strong.object_sigma_per_px = 5.0;
  strong.object_confidence_px = 1.0;
  std::mt19937_64 a(9), b(9);
  const ViewDetections da = SimulateDetections(view, plain, a);
  const ViewDetections db = SimulateDetections(view, strong, b);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(da.keypoints.uv_px.row(k), db.keypoints.uv_px.row(k));
    EXPECT_EQ(da.keypoints.confidence[k], db.keypoints.confidence[k]);
  }
}

TEST(SynthDetectionsTest, OptionsOutOfRangeAreRejected) {
  DetectionNoiseOptions o;
  o.object_sigma_per_px = -1;
  EXPECT_THROW(o.Check("test"), InputError);
  o = DetectionNoiseOptions();
  o.object_confidence_px = 0;
  EXPECT_THROW(o.Check("test"), InputError);
  o = DetectionNoiseOptions();
  o.object_depth_cap_px = -1;
  EXPECT_THROW(o.Check("test"), InputError);
  EXPECT_NO_THROW(DetectionNoiseOptions().Check("test"));
}

}  // namespace
}  // namespace handlabel
