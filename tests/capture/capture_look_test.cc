#include "capture/capture_look.h"

#include <gtest/gtest.h>

#include "capture/rig_presets.h"

namespace handlabel {
namespace {

// A hand-sized set of keypoints 5-10 cm around the workspace centre of the dexycb rig.
Points3d Hand() {
  Points3d k(21, 3);
  for (int i = 0; i < 21; ++i) k.row(i) << 0.005 * (i % 5), 0.02 + 0.004 * i, 0.0;
  return k;
}

TEST(CaptureLook, TheHandCoverHoldsEveryKeypointAndNotTheFarImage) {
  const Rig rig = MakePresetRig(RigPresetOptions(), 0);
  const Points3d hand = Hand();
  for (size_t c = 0; c < rig.size(); ++c) {
    const ImageU8 cover = HandCoverMask(rig[c], hand);
    int covered = 0;
    for (int k = 0; k < 21; ++k) {
      Eigen::Vector2d uv;
      ASSERT_TRUE(rig[c].ProjectWorld(hand.row(k).transpose(), &uv));
      if (!rig[c].camera.InImage(uv)) continue;
      EXPECT_EQ(cover.at(static_cast<int>(uv.x() + 0.5), static_cast<int>(uv.y() + 0.5)),
                255);
      ++covered;
    }
    EXPECT_GT(covered, 0);
    int on = 0;
    for (uint8_t v : cover.data) on += v != 0;
    EXPECT_LT(on, static_cast<int>(cover.data.size()) / 2) << "camera " << c;
  }
}

TEST(CaptureLook, SynthOptionsPlaceHandsAmongTheLabels) {
  std::vector<Points3d> hands;
  for (int i = 0; i < 10; ++i) {
    Points3d k = Hand();
    k.col(0).array() += 0.01 * i;  // centres 0.01 m apart along x
    hands.push_back(k);
  }
  const Rig rig = MakePresetRig(RigPresetOptions(), 0);
  const SynthCaptureOptions o = CaptureLookSynthOptions(rig, hands, nullptr, 7);
  // The median centre: the 6th of the 10 sorted (index 5).
  EXPECT_NEAR(o.scene.workspace_center.x(), Hand().col(0).mean() + 0.05, 1e-12);
  EXPECT_GE(o.scene.workspace_radius, 0.03);
  EXPECT_LE(o.scene.workspace_radius, 0.25);
  EXPECT_EQ(o.seed, 7u);
  EXPECT_EQ(o.view.appearance, SynthAppearance::kRealistic);
  EXPECT_FALSE(o.view.realistic.table);
  EXPECT_NEAR((o.view.realistic.up - RigUp(rig)).norm(), 0, 1e-12);
}

// Cameras looking down at the hand make "up" the way back to them, in any world frame;
// a ring looking in from all sides says nothing, so +z.
TEST(CaptureLook, UpIsAgainstTheCamerasMeanViewingDirection) {
  const Rig preset = MakePresetRig(RigPresetOptions(), 0);  // world z up, cameras above
  EXPECT_GT(RigUp(preset).z(), 0.5);
  // The same rig in the frame of its first camera (the master frame of a recording):
  // up must turn with the world.
  Rig master = preset;
  const Rigid3 world_from_cam0 = preset[0].cam_from_world.Inverse();
  for (size_t c = 0; c < master.size(); ++c) {
    master[c].cam_from_world = preset[c].cam_from_world * world_from_cam0;
  }
  const Eigen::Vector3d up_in_cam0 = preset[0].cam_from_world.rotation * RigUp(preset);
  EXPECT_NEAR((RigUp(master) - up_in_cam0).norm(), 0, 1e-12);
  EXPECT_NEAR(RigUp(master).norm(), 1, 1e-12);
  Rig ring;
  for (int i = 0; i < 6; ++i) {
    const double a = 2 * M_PI * i / 6;
    const Eigen::Vector3d centre(std::cos(a), std::sin(a), 0);
    // Optical axis towards the origin, image y down = world -z.
    Eigen::Matrix3d world_from_cam;
    world_from_cam.col(2) = -centre;
    world_from_cam.col(1) = -Eigen::Vector3d::UnitZ();
    world_from_cam.col(0) = world_from_cam.col(1).cross(world_from_cam.col(2));
    const Eigen::Quaterniond cam_from_world(world_from_cam.transpose());
    ring.Add({"ring" + std::to_string(i), preset[0].camera,
              Rigid3(cam_from_world, -(cam_from_world * centre))});
  }
  EXPECT_EQ(RigUp(ring), Eigen::Vector3d::UnitZ());
}

}  // namespace
}  // namespace handlabel
