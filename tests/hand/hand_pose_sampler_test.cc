#include "hand/hand_pose_sampler.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_lbs.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// Mean distance of the four finger tips (SNAP 8, 12, 16, 20) from the wrist.
double MeanFingerReach(const HandModel& model, const HandPoseVector& pose) {
  HandParams params;
  params.hand_pose = pose;
  const HandMesh mesh = PoseHand(model, params);
  double sum = 0;
  for (int k : {8, 12, 16, 20})
    sum += (mesh.keypoints.row(k) - mesh.keypoints.row(0)).norm();
  return sum / 4;
}

double TipDistance(const HandModel& model, const HandPoseVector& pose, int a, int b) {
  HandParams params;
  params.hand_pose = pose;
  const HandMesh mesh = PoseHand(model, params);
  return (mesh.keypoints.row(a) - mesh.keypoints.row(b)).norm();
}

TEST(HandPoseSampler, EveryKindStaysWithinLimitsOnBothSides) {
  for (HandSide side : {HandSide::kRight, HandSide::kLeft}) {
    const HandAnatomy anatomy = ComputeHandAnatomy(MakeCapsuleHand(side));
    for (const HandLimits& limits : {DefaultHandLimits(), AnchorHandLimits()}) {
      for (HandPoseKind kind :
           {HandPoseKind::kOpen, HandPoseKind::kFist, HandPoseKind::kPinch,
            HandPoseKind::kPoint, HandPoseKind::kRandom}) {
        for (int i = 0; i < 40; ++i) {
          const SampledHandPose s =
              SampleHandPoseOfKind(anatomy, limits, kind, 8.0, testing::TestRng());
          // Re-derive the angles from the axis-angle pose instead of trusting s.angles.
          HandPoseVector angles;
          HandAnatomicalAngles(anatomy, s.hand_pose.data(), angles.data());
          EXPECT_THAT(angles, testing::MatrixNear(s.angles, 1e-9));
          int worst = -1;
          EXPECT_TRUE(AnglesWithinLimits(limits, angles))
              << HandPoseKindName(kind) << " violates by "
              << MaxLimitViolationDeg(limits, angles, &worst) << " deg at " << worst;
        }
      }
    }
  }
}

TEST(HandPoseSampler, KindsLookLikeTheirNames) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  const HandLimits limits = DefaultHandLimits();
  auto sample = [&](HandPoseKind kind) {
    return SampleHandPoseOfKind(anatomy, limits, kind, 3.0, testing::TestRng()).hand_pose;
  };
  for (int i = 0; i < 10; ++i) {
    const HandPoseVector open = sample(HandPoseKind::kOpen);
    const HandPoseVector fist = sample(HandPoseKind::kFist);
    const HandPoseVector point = sample(HandPoseKind::kPoint);
    const HandPoseVector pinch = sample(HandPoseKind::kPinch);
    EXPECT_GT(MeanFingerReach(model, open), 1.3 * MeanFingerReach(model, fist));
    // Pointing: index tip (8) far from the wrist, middle tip (12) curled in.
    EXPECT_GT(TipDistance(model, point, 8, 0), 1.4 * TipDistance(model, point, 12, 0));
    // Pinch brings thumb tip (4) and index tip (8) closer than the open hand.
    EXPECT_LT(TipDistance(model, pinch, 4, 8), TipDistance(model, open, 4, 8));
  }
}

TEST(HandPoseSampler, DrawsKindsByWeightAndChecksOptions) {
  const HandAnatomy anatomy = ComputeHandAnatomy(MakeCapsuleHand(HandSide::kRight));
  HandPoseSamplerOptions options;
  options.weight_open = 0;
  options.weight_fist = 0;
  options.weight_pinch = 0;
  options.weight_random = 0;
  for (int i = 0; i < 10; ++i) {
    EXPECT_EQ(
        SampleHandPose(anatomy, DefaultHandLimits(), options, testing::TestRng()).kind,
        HandPoseKind::kPoint);
  }
  options.weight_point = 0;
  EXPECT_THROW(options.Check("test"), InputError);
  options.weight_point = 1;
  options.jitter_deg = -1;
  EXPECT_THROW(options.Check("test"), InputError);
}

}  // namespace
}  // namespace handlabel
