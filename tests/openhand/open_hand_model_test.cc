// The shipped models/open_hand_{right,left}.npz: loadable, plausible, mirror pair,
// and equal to what the builder's defaults produce (checked on the arrays' key
// properties here; the full rebuild within 1e-9 is `scripts/check-open-hand`).
#include <gtest/gtest.h>

#include "hand/hand_model_io.h"
#include "hand/hand_pose_sampler.h"
#include "openhand/mesh_checks.h"
#include "tests/openhand/open_hand_checks.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string ModelPath(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/models/" + name;
}

const HandModel& ShippedRight() {
  static const HandModel m = LoadHandModel(ModelPath("open_hand_right.npz"));
  return m;
}
const HandModel& ShippedLeft() {
  static const HandModel m = LoadHandModel(ModelPath("open_hand_left.npz"));
  return m;
}

TEST(ShippedOpenHand, RightIsAPlausibleClosedHand) {
  const HandModel& m = ShippedRight();
  EXPECT_EQ(m.name, "open_hand_right");
  EXPECT_EQ(m.side, HandSide::kRight);
  EXPECT_EQ(m.num_vertices(), 778);
  EXPECT_EQ(m.num_betas(), 10);
  testing::ExpectPlausibleOpenHand(m);
}

TEST(ShippedOpenHand, LeftIsTheMirrorOfRight) {
  EXPECT_EQ(ShippedLeft().name, "open_hand_left");
  EXPECT_EQ(ShippedLeft().side, HandSide::kLeft);
  testing::ExpectMirrorPair(ShippedRight(), ShippedLeft());
  testing::ExpectPlausibleOpenHand(ShippedLeft());
}

TEST(ShippedOpenHand, SaveLoadRoundTripIsExact) {
  const std::string path = testing::ScratchDir() + "/again.npz";
  SaveHandModel(ShippedRight(), path);
  const HandModel again = LoadHandModel(path);
  EXPECT_TRUE(again.v_template == ShippedRight().v_template);
  EXPECT_TRUE(again.shapedirs == ShippedRight().shapedirs);
  EXPECT_TRUE(again.skinning_weights == ShippedRight().skinning_weights);
}

TEST(ShippedOpenHand, ShapeSpaceStaysSaneAtThreeSigma) {
  // Every beta at +-3: still closed (topology does not change), no inverted faces
  // relative to the rest normals, and a hand length in a broad human range.
  const HandModel& m = ShippedRight();
  for (int k = 0; k < m.num_betas(); ++k) {
    for (double b : {-3.0, 3.0}) {
      HandParams p;
      p.betas = Eigen::VectorXd::Zero(m.num_betas());
      p.betas[k] = b;
      const HandMesh mesh = PoseHand(m, p);
      EXPECT_GT(SignedVolume(mesh.vertices, m.faces), 0.0);
      EXPECT_EQ(InvertedFaceFraction(m, p), 0.0) << "beta " << k << " = " << b;
      const double length = (mesh.keypoints.row(0) - mesh.keypoints.row(12)).norm();
      EXPECT_GT(length, 0.15);
      EXPECT_LT(length, 0.23);
    }
  }
}

TEST(ShippedOpenHand, NaturalPosesKeepFacesTheRightWayRound) {
  // Sampled natural poses (all kinds, limits of DefaultHandLimits): measured worst
  // fraction of inverted faces stays small.
  const HandModel& m = ShippedRight();
  const HandAnatomy anatomy = ComputeHandAnatomy(m);
  std::mt19937_64 rng(testing::TestSeed());
  double worst = 0.0;
  for (int i = 0; i < 40; ++i) {
    HandParams p;
    p.hand_pose = SampleHandPose(anatomy, DefaultHandLimits(), {}, rng).hand_pose;
    worst = std::max(worst, InvertedFaceFraction(m, p));
  }
  EXPECT_LT(worst, 0.02);
}

TEST(ShippedOpenHand, ThumbOpposesEveryFingerWithinTheLimits) {
  // Random search over the thumb's and one finger's angles within DefaultHandLimits:
  // the thumb tip reaches the fingertip (measured: 3-5 mm apart with 3000 samples).
  const HandModel& m = ShippedRight();
  const HandAnatomy anatomy = ComputeHandAnatomy(m);
  const HandLimits limits = DefaultHandLimits();
  std::mt19937_64 rng(testing::TestSeed());
  const int first_joint[4] = {1, 4, 10, 7};  // index, middle, ring, pinky
  const int tip_keypoint[4] = {8, 12, 16, 20};
  for (int f = 0; f < 4; ++f) {
    double best = 1e9;
    for (int i = 0; i < 800; ++i) {
      HandPoseVector angles = HandPoseVector::Zero();
      for (int j : {13, 14, 15, first_joint[f], first_joint[f] + 1, first_joint[f] + 2}) {
        for (int a = 0; a < 3; ++a) {
          std::uniform_real_distribution<double> deg(limits.joints[j][a].min_deg,
                                                     limits.joints[j][a].max_deg);
          angles[3 * (j - 1) + a] = deg(rng) * M_PI / 180.0;
        }
      }
      HandParams p;
      p.hand_pose = HandPoseFromAnatomicalAngles(anatomy, angles);
      const HandMesh h = PoseHand(m, p);
      best =
          std::min(best, (h.keypoints.row(4) - h.keypoints.row(tip_keypoint[f])).norm());
    }
    EXPECT_LT(best, 0.015) << "finger " << f;
  }
}

}  // namespace
}  // namespace handlabel
