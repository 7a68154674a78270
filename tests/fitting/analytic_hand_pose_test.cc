#include "fitting/analytic_hand_pose.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "hand/capsule_hand.h"
#include "hand/hand_lbs.h"
#include "tests/fitting/fitting_scene.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// With the true shape and wrist rotation, laying every bone along its target puts every
// keypoint exactly where the target is: twist about a bone never moves the bone's end.
// (Pose blend shapes do depend on the twist, so they are switched off here.)
TEST(AnalyticHandPose, ReproducesTheKeypointsOfARandomPoseExactly) {
  HandModel model = MakeCapsuleHand(HandSide::kRight);
  model.posedirs.setZero();
  for (int trial = 0; trial < 5; ++trial) {
    const testing::SceneFrame frame =
        testing::RandomSceneFrame(model, testing::TestRng());
    HandParams rest_params;
    rest_params.betas = frame.params.betas;
    const Points3d rest = PoseHand(model, rest_params).keypoints;
    const Eigen::Matrix3d root =
        Eigen::AngleAxisd(frame.params.global_orient.norm(),
                          frame.params.global_orient.normalized())
            .toRotationMatrix();
    HandParams found = frame.params;
    AnalyticHandPose(rest, frame.mesh.keypoints, Eigen::VectorXd::Ones(21), root,
                     found.hand_pose.data());
    const Points3d posed = PoseHand(model, found).keypoints;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      EXPECT_LT((posed.row(k) - frame.mesh.keypoints.row(k)).norm(), 1e-9)
          << "trial " << trial << " keypoint " << k;
    }
  }
}

TEST(AnalyticHandPose, UnknownKeypointsLeaveTheirJointsUnturned) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const testing::SceneFrame frame = testing::RandomSceneFrame(model, testing::TestRng());
  const Points3d rest = PoseHand(model, HandParams()).keypoints;
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(21);
  weights[8] = 0;  // index tip (SNAP 8): the index DIP (native 3) has no bone target
  double pose[45];
  AnalyticHandPose(rest, frame.mesh.keypoints, weights, Eigen::Matrix3d::Identity(),
                   pose);
  for (int c = 0; c < 3; ++c) EXPECT_EQ(pose[3 * (3 - 1) + c], 0.0);
  EXPECT_NE(Eigen::Map<Eigen::Vector3d>(pose).norm(), 0.0);  // the index MCP still turns
}

}  // namespace
}  // namespace handlabel
