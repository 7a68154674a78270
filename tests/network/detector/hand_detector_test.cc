// Video mode's region of a view: the previous frame's 3D hand projected through the
// view's camera, boxed by MediaPipe's tracking rule (RoiOfTrackedHand), checked against
// the rule worked out by hand on a hand whose projection is known.

#include <gtest/gtest.h>

#include "network/detector/hand_detector.h"

namespace handlabel {
namespace {

constexpr int kWidth = 400, kHeight = 300;
constexpr double kFocal = 500, kDepth = 0.5;

// TestCamera: a pinhole camera at the world origin looking along +z, moved `shift_x`
// metres along its x axis (cam_from_world translation -shift_x).
RigCamera TestCamera(double shift_x = 0) {
  RigCamera camera;
  camera.name = "cam";
  camera.camera = Camera::Pinhole(kFocal, kFocal, 200, 150, kWidth, kHeight);
  camera.cam_from_world =
      Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-shift_x, 0, 0));
  return camera;
}

// An upright hand (fingers up) seen by TestCamera(): wrist at pixel (100, 200), five
// fingers of four joints at x = 70, 85, 100, 115, 130, from y = 160 upwards in 20 px
// steps, all at depth kDepth: the previous frame's triangulated hand.
FrameHandResult PreviousFrameWithUprightHand() {
  FrameHandResult previous;
  previous.found = true;
  const auto lift = [](double u, double v) {
    return Eigen::Vector3d((u - 200) * kDepth / kFocal, (v - 150) * kDepth / kFocal,
                           kDepth);
  };
  previous.keypoints3d.row(0) = lift(100, 200).transpose();
  for (int f = 0; f < 5; ++f) {
    for (int j = 0; j < 4; ++j) {
      previous.keypoints3d.row(1 + 4 * f + j) =
          lift(70 + 15 * f, 160 - 20 * j).transpose();
    }
  }
  previous.keypoint3d_valid.fill(true);
  return previous;
}

TEST(HandDetectorVideo, TrackedRoiIsTheProjectedHandsMediapipeRoi) {
  const FrameHandResult previous = PreviousFrameWithUprightHand();
  const auto roi = RoiOfTrackedHand(TestCamera(), previous, {}, kWidth, kHeight);
  ASSERT_TRUE(roi);
  // By hand: the joints MediaPipe boxes (0-3, 5, 6, 9, 10, 13, 14, 17, 18) span x 70..130
  // and y 120..200; wrist -> mean of the index, middle and ring MCPs points straight up,
  // so no rotation; centre (100, 160) moved 0.1 box heights (8 px) towards the fingers;
  // side 2 x the 80 px long side. MediaPipe's continuous coordinates are ours + 0.5.
  EXPECT_NEAR(roi->rotation, 0.0, 1e-9);
  EXPECT_NEAR(roi->x_center * kWidth, 100.5, 1e-6);
  EXPECT_NEAR(roi->y_center * kHeight, 160.5 - 8.0, 1e-6);
  EXPECT_NEAR(roi->width * kWidth, 160.0, 1e-6);
  EXPECT_NEAR(roi->height * kHeight, 160.0, 1e-6);

  // A camera 2 cm to the right sees the hand kFocal * 0.02 / kDepth = 20 px to the left.
  const auto moved = RoiOfTrackedHand(TestCamera(0.02), previous, {}, kWidth, kHeight);
  ASSERT_TRUE(moved);
  EXPECT_NEAR(moved->x_center * kWidth, 100.5 - 20.0, 1e-6);
  EXPECT_NEAR(moved->y_center * kHeight, 160.5 - 8.0, 1e-6);
  EXPECT_NEAR(moved->width * kWidth, 160.0, 1e-6);
}

TEST(HandDetectorVideo, TrackedRoiNeedsAWristAHandInFrontAndMostOfItInTheImage) {
  const FrameHandResult previous = PreviousFrameWithUprightHand();
  FrameHandResult no_wrist = previous;
  no_wrist.keypoint3d_valid[0] = false;
  EXPECT_FALSE(RoiOfTrackedHand(TestCamera(), no_wrist, {}, kWidth, kHeight));

  FrameHandResult behind = previous;
  behind.keypoints3d.col(2) *= -1.0;
  EXPECT_FALSE(RoiOfTrackedHand(TestCamera(), behind, {}, kWidth, kHeight));

  // 0.13 m to the left at 0.5 m is 130 px: the hand (x 70..130) is then mostly left of
  // the image (4 of 21 keypoints at x >= -0.5).
  FrameHandResult left = previous;
  left.keypoints3d.col(0).array() -= 0.13;
  EXPECT_FALSE(RoiOfTrackedHand(TestCamera(), left, {}, kWidth, kHeight));
  MultiViewDetectorOptions any_part;
  any_part.min_keypoints_in_view = 0.0;
  EXPECT_TRUE(RoiOfTrackedHand(TestCamera(), left, any_part, kWidth, kHeight));

  // A keypoint the previous frame could not triangulate stands at the wrist: the ROI
  // is still made, from the others.
  FrameHandResult one_missing = previous;
  one_missing.keypoint3d_valid[20] = false;
  EXPECT_TRUE(RoiOfTrackedHand(TestCamera(), one_missing, {}, kWidth, kHeight));
}

}  // namespace
}  // namespace handlabel
