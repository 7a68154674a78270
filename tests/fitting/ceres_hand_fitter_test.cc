#include "fitting/ceres_hand_fitter.h"

#include <gtest/gtest.h>

#include "core/capsule_hand.h"
#include "core/errors.h"
#include "core/metrics.h"
#include "fitting/silhouette_render.h"
#include "tests/fitting/fitting_scene.h"
#include "tests/fitting/tube_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

class CeresHandFitterTest : public ::testing::Test {
 protected:
  HandModel model_ = MakeCapsuleHand(HandSide::kRight);
};

TEST_F(CeresHandFitterTest, OptionsCheck) {
  HandFitOptions o;
  o.keypoint_sigma_px = 0.0;
  EXPECT_THROW(o.Check(), InputError);
  o = {};
  o.silhouette_vertex_stride = 0;
  EXPECT_THROW(o.Check(), InputError);
  HandFitConfig c;
  c.pose_pca_comps = 7;
  EXPECT_THROW(c.Check(), InputError);
  EXPECT_THROW(CeresHandFitter(model_, c), InputError);
}

TEST_F(CeresHandFitterTest, InitFromExact3dKeypoints) {
  const CeresHandFitter fitter(model_);
  for (int trial = 0; trial < 3; ++trial) {
    const testing::SceneFrame frame =
        testing::RandomSceneFrame(model_, testing::TestRng());
    const HandParams init =
        fitter.InitFromKeypoints3d(frame.mesh.keypoints, Eigen::VectorXd::Ones(21));
    const HandMesh mesh = PoseHand(model_, init);
    EXPECT_LT(MeanPointError(mesh.keypoints, frame.mesh.keypoints), 0.003) << trial;
  }
}

TEST_F(CeresHandFitterTest, NoiseFreeKeypointsFromTriangulationBaseline) {
  const CeresHandFitter fitter(model_);
  for (int trial = 0; trial < 3; ++trial) {
    const testing::SceneFrame frame =
        testing::RandomSceneFrame(model_, testing::TestRng());
    HandFitInput input;
    input.views = frame.views;
    const HandParams init = fitter.InitFromViews(input.views);
    const HandFitResult result = fitter.Fit(input, init);
    EXPECT_LT(MeanPointError(result.keypoints, frame.mesh.keypoints), 0.0005) << trial;
    ASSERT_EQ(result.view_rms_px.size(), 8u);
    for (double rms : result.view_rms_px) EXPECT_LT(rms, 0.5);
    EXPECT_GT(result.iterations, 0);
    EXPECT_TRUE(result.term_costs.count("keypoints"));
    EXPECT_TRUE(result.term_costs.count("joint_limits"));
  }
}

TEST_F(CeresHandFitterTest, RobustLossBeatsLeastSquaresWithOutliers) {
  HandFitOptions robust_options;
  HandFitOptions plain_options;
  plain_options.keypoint_loss.type = RobustLossType::kTrivial;
  const CeresHandFitter robust(model_, {}, robust_options);
  const CeresHandFitter plain(model_, {}, plain_options);
  double robust_error = 0.0, plain_error = 0.0;
  for (int trial = 0; trial < 3; ++trial) {
    testing::SceneFrame frame = testing::RandomSceneFrame(model_, testing::TestRng());
    testing::CorruptViews(&frame.views, 2.0, 0.1, {3}, testing::TestRng());
    HandFitInput input;
    input.views = frame.views;
    const HandParams init = robust.InitFromViews(input.views);
    robust_error +=
        MeanPointError(robust.Fit(input, init).keypoints, frame.mesh.keypoints);
    plain_error += MeanPointError(plain.Fit(input, init).keypoints, frame.mesh.keypoints);
  }
  EXPECT_LT(robust_error / 3, 0.006);
  EXPECT_LT(robust_error, plain_error);
}

TEST_F(CeresHandFitterTest, ResultWithinJointLimits) {
  const CeresHandFitter fitter(model_);
  const HandAnatomy anatomy = ComputeHandAnatomy(model_);
  testing::SceneFrame frame = testing::RandomSceneFrame(model_, testing::TestRng());
  testing::CorruptViews(&frame.views, 2.0, 0.1, {}, testing::TestRng());
  HandFitInput input;
  input.views = frame.views;
  const HandFitResult result = fitter.Fit(input, fitter.InitFromViews(input.views));
  HandPoseVector angles;
  HandAnatomicalAngles(anatomy, result.params.hand_pose.data(), angles.data());
  EXPECT_LT(MaxLimitViolationDeg(DefaultHandLimits(), angles), 5.0);
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// Masks of the ground-truth mesh in every view (the rasteriser of core).
std::vector<MaskImage> RenderMasks(const HandModel& model,
                                   const testing::SceneFrame& frame,
                                   const std::vector<PixelRays>& rays) {
  std::vector<MaskImage> masks;
  for (size_t v = 0; v < frame.views.size(); ++v) {
    masks.push_back(
        RenderHandMask(frame.mesh.vertices, model.faces, frame.views[v].camera, rays[v]));
  }
  return masks;
}

// The tube hand, not the capsule hand: with the capsule hand the same fit reaches
// only 1.6-2.0 mm vertex error and IoU 0.87-0.90 (below this test's bounds).
TEST(CeresHandFitterSilhouetteTest, NoiseFreeKeypointsAndMasks) {
  const HandModel model = testing::MakeTubeHand();
  HandFitOptions options;
  options.silhouette_vertex_stride = 4;  // keeps the test fast
  options.silhouette_rounds = 2;
  const CeresHandFitter fitter(model, {}, options);
  std::vector<PixelRays> rays;
  for (const RigCamera& cam : testing::DexYcbLikeRig(0.5)) rays.emplace_back(cam.camera);
  for (int trial = 0; trial < 2; ++trial) {
    const testing::SceneFrame frame =
        testing::RandomSceneFrame(model, testing::TestRng());
    HandFitInput input;
    input.views = frame.views;
    input.masks = RenderMasks(model, frame, rays);
    input.pixel_rays = &rays;
    const HandFitResult result = fitter.Fit(input, fitter.InitFromViews(input.views));
    EXPECT_LT(MeanPointError(result.keypoints, frame.mesh.keypoints), 0.001) << trial;
    EXPECT_LT(MeanPointError(result.vertices, frame.mesh.vertices), 0.0015) << trial;
    ASSERT_EQ(result.view_iou.size(), 8u);
    for (double iou : result.view_iou) EXPECT_GT(iou, 0.9);
    EXPECT_TRUE(result.term_costs.count("silhouette"));
  }
}

}  // namespace
}  // namespace handlabel
