#include "hand/hand_anatomy.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "geometry/dual.h"
#include "hand/capsule_hand.h"
#include "hand/hand_lbs.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MatrixNear;
using testing::Uniform;

constexpr double kDeg = M_PI / 180.0;

HandPoseVector AnglesOf(const HandAnatomy& anatomy, const HandPoseVector& pose) {
  HandPoseVector angles;
  HandAnatomicalAngles(anatomy, pose.data(), angles.data());
  return angles;
}

// Rest position of native joint v (v < 16) or of fingertip v - 16 (thumb, index,
// middle, ring, pinky).
Eigen::Vector3d RestPoint(const HandModel& model, int v) {
  if (v >= kNumHandJoints) return model.v_template.row(model.tip_vertex_ids[v - 16]);
  return (model.joint_regressor.row(v) * model.v_template).transpose();
}

HandPoseVector MirrorPose(const HandPoseVector& pose) {
  HandPoseVector out = pose;
  for (int j = 0; j < 15; ++j) {
    out[3 * j + 1] = -out[3 * j + 1];
    out[3 * j + 2] = -out[3 * j + 2];
  }
  return out;
}

TEST(HandAnatomy, FramesAreRotationsAndFollowTheBones) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  for (int j = 1; j < kNumHandJoints; ++j) {
    const Eigen::Matrix3d& f = anatomy.frames[j];
    EXPECT_THAT(f.transpose() * f, MatrixNear(Eigen::Matrix3d::Identity(), 1e-12));
    EXPECT_NEAR(f.determinant(), 1.0, 1e-12) << JointName(j);
    // b points from the child back to the joint.
    const int child = j % 3 == 0 ? -1 : j + 1;
    const Eigen::Vector3d c = child > 0 ? RestPoint(model, child)
                                        : RestPoint(model, j == 15   ? 16
                                                           : j == 3  ? 17
                                                           : j == 6  ? 18
                                                           : j == 12 ? 19
                                                                     : 20);
    const Eigen::Vector3d b = (RestPoint(model, j) - c).normalized();
    EXPECT_THAT(f.col(kTwist), MatrixNear(b, 1e-12)) << JointName(j);
  }
  // Straight index finger along -x: b = +x, u = +y, l = +z.
  for (int j = 1; j <= 3; ++j) {
    EXPECT_THAT(anatomy.frames[j], MatrixNear(Eigen::Matrix3d::Identity(), 1e-12));
  }
}

TEST(HandAnatomy, RecoversKnownAnglesForEveryJoint) {
  for (HandSide side : {HandSide::kRight, HandSide::kLeft}) {
    const HandAnatomy anatomy = ComputeHandAnatomy(MakeCapsuleHand(side));
    for (int trial = 0; trial < 50; ++trial) {
      HandPoseVector angles;
      for (int i = 0; i < 45; ++i) {
        angles[i] = (i % 3 == kSpread ? Uniform(-80, 80) : Uniform(-170, 170)) * kDeg;
      }
      const HandPoseVector pose = HandPoseFromAnatomicalAngles(anatomy, angles);
      EXPECT_THAT(AnglesOf(anatomy, pose), MatrixNear(angles, 1e-9));
    }
  }
}

TEST(HandAnatomy, SingleAxisMotionsOfAStraightFinger) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  // Index MCP frame is the identity, so rotations about world x, y, z are pure twist,
  // spread and bend.
  for (int axis = 0; axis < 3; ++axis) {
    Eigen::Vector3d w = Eigen::Vector3d::Zero();
    w[axis] = 0.4;
    Eigen::Vector3d angles;
    AnatomicalAngles(anatomy, 1, w.data(), angles.data());
    EXPECT_THAT(angles, MatrixNear(w, 1e-12));
  }
  // Positive bend is flexion: the fingertip moves towards the palm (-y); positive
  // spread moves the index towards the thumb (+z).
  HandParams params;
  params.hand_pose.segment<3>(0) =
      AxisAngleFromAnatomicalAngles(anatomy, 1, Eigen::Vector3d(0, 0, 40 * kDeg));
  const HandMesh flexed = PoseHand(model, params);
  const HandMesh rest = PoseHand(model, HandParams());
  EXPECT_LT(flexed.keypoints(8, 1), rest.keypoints(8, 1) - 0.02);  // SNAP 8 = index tip
  params.hand_pose.segment<3>(0) =
      AxisAngleFromAnatomicalAngles(anatomy, 1, Eigen::Vector3d(0, 15 * kDeg, 0));
  EXPECT_GT(PoseHand(model, params).keypoints(8, 2), rest.keypoints(8, 2) + 0.01);
}

TEST(HandAnatomy, MirroredLeftHandGivesTheSameAnglesAndMirroredMesh) {
  const HandModel right = MakeCapsuleHand(HandSide::kRight);
  const HandModel left = MakeCapsuleHand(HandSide::kLeft);
  const HandAnatomy right_anatomy = ComputeHandAnatomy(right);
  const HandAnatomy left_anatomy = ComputeHandAnatomy(left);
  for (int trial = 0; trial < 20; ++trial) {
    HandParams p;
    for (int i = 0; i < 45; ++i) p.hand_pose[i] = Uniform(-1, 1);
    p.global_orient = testing::RandomVector3(-1, 1);
    p.betas = Eigen::VectorXd::Random(10);
    p.transl = testing::RandomVector3(-0.1, 0.1);
    HandParams q = p;
    q.hand_pose = MirrorPose(p.hand_pose);
    q.global_orient =
        Eigen::Vector3d(p.global_orient.x(), -p.global_orient.y(), -p.global_orient.z());
    q.transl.x() = -p.transl.x();
    EXPECT_THAT(AnglesOf(left_anatomy, q.hand_pose),
                MatrixNear(AnglesOf(right_anatomy, p.hand_pose), 1e-12));
    Points3d mirrored = PoseHand(right, p).vertices;
    mirrored.col(0) *= -1.0;
    EXPECT_THAT(PoseHand(left, q).vertices, MatrixNear(mirrored, 1e-12));
  }
  // Angles -> pose on the left side is the mirror of the right side's.
  HandPoseVector angles;
  for (int i = 0; i < 45; ++i) angles[i] = Uniform(-1, 1);
  EXPECT_THAT(
      HandPoseFromAnatomicalAngles(left_anatomy, angles),
      MatrixNear(MirrorPose(HandPoseFromAnatomicalAngles(right_anatomy, angles)), 1e-12));
}

TEST(HandAnatomy, DualDerivativesOfAnglesMatchFiniteDifferences) {
  const HandAnatomy anatomy = ComputeHandAnatomy(MakeCapsuleHand(HandSide::kLeft));
  for (int j : {1, 5, 13, 15}) {
    for (double scale : {0.0, 0.6}) {
      const Eigen::Vector3d w = scale * testing::RandomVector3(-1, 1);
      Dual<3> wd[3] = {Dual<3>(w[0], 0), Dual<3>(w[1], 1), Dual<3>(w[2], 2)};
      Dual<3> ad[3];
      AnatomicalAngles(anatomy, j, wd, ad);
      for (int k = 0; k < 3; ++k) {
        const double h = 1e-6;
        Eigen::Vector3d wp = w, wm = w, ap, am;
        wp[k] += h;
        wm[k] -= h;
        AnatomicalAngles(anatomy, j, wp.data(), ap.data());
        AnatomicalAngles(anatomy, j, wm.data(), am.data());
        for (int a = 0; a < 3; ++a) {
          EXPECT_NEAR(ad[a].v[k], (ap[a] - am[a]) / (2 * h), 1e-8)
              << JointName(j) << " angle " << a << " param " << k;
        }
      }
    }
  }
}

TEST(HandAnatomy, RejectsModelsOutsideMANOLayout) {
  HandModel model = MakeCapsuleHand(HandSide::kRight);
  // Rotate the whole hand so that the fingers point along +y (parallel to "up").
  for (int v = 0; v < model.num_vertices(); ++v) {
    const Eigen::Vector3d p = model.v_template.row(v).transpose();
    model.v_template.row(v) << p.y(), -p.x(), p.z();
  }
  EXPECT_THROW(ComputeHandAnatomy(model), InputError);
}

TEST(HandLimits, AnchorTableMatchesHandModelMd) {
  const HandLimits anchor = AnchorHandLimits();
  auto expect = [&](int j, std::array<double, 6> v) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_EQ(anchor.joints[j][a].min_deg, v[2 * a]) << JointName(j) << " " << a;
      EXPECT_EQ(anchor.joints[j][a].max_deg, v[2 * a + 1]) << JointName(j) << " " << a;
    }
  };
  expect(13, {-45, 45, -15, 45, 0, 45});  // thumb CMC
  expect(14, {0, 0, -10, 10, 0, 90});     // thumb MCP
  expect(15, {0, 0, 0, 0, 0, 90});        // thumb IP
  for (int mcp : {1, 4, 7, 10}) {
    expect(mcp, {0, 0, -5, 5, 0, 90});
    expect(mcp + 1, {0, 0, 0, 0, 0, 90});
    expect(mcp + 2, {0, 0, 0, 0, 0, 90});
  }
  EXPECT_EQ(JointName(13), "thumb_cmc");
  EXPECT_EQ(JointName(11), "ring_pip");
  EXPECT_EQ(JointType(9), HandJointType::kFingerDip);
}

TEST(HandLimits, DefaultsContainTheAnchorTableAndValidate) {
  const HandLimits anchor = AnchorHandLimits();
  const HandLimits tuned = DefaultHandLimits();
  tuned.Check("DefaultHandLimits");
  for (int j = 1; j < kNumHandJoints; ++j) {
    for (int a = 0; a < 3; ++a) {
      EXPECT_LE(tuned.joints[j][a].min_deg, anchor.joints[j][a].min_deg);
      EXPECT_GE(tuned.joints[j][a].max_deg, anchor.joints[j][a].max_deg);
      // No zero-width hinge left.
      EXPECT_GT(tuned.joints[j][a].max_deg - tuned.joints[j][a].min_deg, 10.0);
    }
  }
  HandLimits bad = tuned;
  bad.joints[5][kBend] = {10, -10};
  EXPECT_THROW(bad.Check("test"), InputError);
}

TEST(HandLimits, ResidualsAreHingesAndAgreeWithViolation) {
  const HandLimits limits = DefaultHandLimits();
  HandPoseVector angles = HandPoseVector::Zero();
  HandPoseVector residuals;
  LimitResiduals(limits, angles.data(), residuals.data());
  EXPECT_EQ(residuals.norm(), 0.0);
  EXPECT_TRUE(AnglesWithinLimits(limits, angles));
  angles[3 * (5 - 1) + kBend] = 120 * kDeg;     // middle PIP bend over 110
  angles[3 * (13 - 1) + kSpread] = -25 * kDeg;  // thumb CMC spread under -15
  LimitResiduals(limits, angles.data(), residuals.data());
  HandPoseVector expected = HandPoseVector::Zero();
  expected[3 * (5 - 1) + kBend] = 10 * kDeg;
  expected[3 * (13 - 1) + kSpread] = 10 * kDeg;
  EXPECT_THAT(residuals, MatrixNear(expected, 1e-12));
  int worst = -1;
  EXPECT_NEAR(MaxLimitViolationDeg(limits, angles, &worst), 10.0, 1e-9);
  EXPECT_FALSE(AnglesWithinLimits(limits, angles));
  angles[0] = std::nan("");
  EXPECT_FALSE(AnglesWithinLimits(limits, angles));
}

}  // namespace
}  // namespace handlabel
