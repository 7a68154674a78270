#include "fitting/ceres_hand_fitter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/errors.h"
#include "fitting/silhouette_render.h"
#include "hand/capsule_hand.h"
#include "hand/metrics.h"
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
  EXPECT_THROW(o.Check("HandFitOptions"), InputError);
  o = {};
  o.silhouette_vertex_stride = 0;
  EXPECT_THROW(o.Check("HandFitOptions"), InputError);
  // Fractional negatives of double fields (an int check would truncate them to 0).
  o = {};
  o.mask_margin_max_px = -0.5;
  EXPECT_THROW(o.Check("HandFitOptions"), InputError);
  o = {};
  o.rigid_skip_below_px = -0.5;
  EXPECT_THROW(o.Check("HandFitOptions"), InputError);
  HandFitConfig c;
  c.pose_pca_comps = 7;
  EXPECT_THROW(c.Check("HandFitConfig"), InputError);
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

// 2D keypoints in one view leave the distance along its rays free: such fits ended
// metres off with a small reprojection error. The fit refuses them by name, unless 3D
// targets (a network answer) place the hand.
TEST_F(CeresHandFitterTest, KeypointsOfOneViewFailByNameUnless3dTargetsPlaceTheHand) {
  const CeresHandFitter fitter(model_);
  const testing::SceneFrame frame = testing::RandomSceneFrame(model_, testing::TestRng());
  HandFitInput one_view;
  one_view.views = frame.views;
  for (size_t v = 0; v < one_view.views.size(); ++v) {
    if (v != 2) one_view.views[v].keypoints.confidence.setZero();
  }
  const std::string camera = frame.views[2].camera.name;
  ASSERT_FALSE(camera.empty());
  EXPECT_EQ(ViewsWithKeypoints(one_view.views), std::vector<std::string>{camera});
  const HandParams start = fitter.InitFromViews(one_view.views);
  try {
    fitter.Fit(one_view, start);
    ADD_FAILURE() << "a fit from one view of 2D was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2D keypoints in only 1 view (" + camera + ")"),
              std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("depth is not determined"), std::string::npos);
  }
  // Positions that are not finite do not count as a view's keypoints.
  HandFitInput none = one_view;
  none.views[2].keypoints.uv_px.setConstant(std::nan(""));
  EXPECT_TRUE(ViewsWithKeypoints(none.views).empty());
  try {
    fitter.Fit(none, start);
    ADD_FAILURE() << "a fit from no 2D was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("2D keypoints in no view"), std::string::npos)
        << e.what();
  }
  // With 3D targets the one view refines a hand they place.
  HandFitInput placed = one_view;
  placed.targets3d.emplace();
  placed.targets3d->keypoints = frame.mesh.keypoints;
  placed.targets3d->keypoint_weights = Eigen::VectorXd::Ones(kNumHandKeypoints);
  const HandFitResult refined = fitter.Fit(
      placed, fitter.InitFromKeypoints3d(frame.mesh.keypoints,
                                         Eigen::VectorXd::Ones(kNumHandKeypoints)));
  EXPECT_LT(MeanPointError(refined.keypoints, frame.mesh.keypoints), 0.003);
  // A second view with a single keypoint is enough to be accepted.
  HandFitInput two_views = one_view;
  two_views.views[5].keypoints.confidence[8] = 1.0;
  EXPECT_EQ(ViewsWithKeypoints(two_views.views).size(), 2u);
  EXPECT_NO_THROW(fitter.Fit(two_views, fitter.InitFromViews(two_views.views)));
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

// The tube hand, its fitter with silhouettes and the half-size DexYCB-like rig's pixel
// rays.
struct SilhouetteScene {
  HandModel model = testing::MakeTubeHand();
  CeresHandFitter fitter{model, {}, Options()};
  std::vector<PixelRays> rays = Rays();

  static HandFitOptions Options() {
    HandFitOptions options;
    options.silhouette_vertex_stride = 4;  // keeps the tests fast
    options.silhouette_rounds = 2;
    return options;
  }
  static std::vector<PixelRays> Rays() {
    std::vector<PixelRays> rays;
    for (const RigCamera& cam : testing::DexYcbLikeRig(0.5))
      rays.emplace_back(cam.camera);
    return rays;
  }
  // A random frame (testing::TestRng) with its exact keypoints and rendered masks.
  std::pair<testing::SceneFrame, HandFitInput> NextTrial() const {
    const testing::SceneFrame frame =
        testing::RandomSceneFrame(model, testing::TestRng());
    HandFitInput input;
    input.views = frame.views;
    input.masks = RenderMasks(model, frame, rays);
    return {frame, input};
  }
};

// The tube hand, not the capsule hand: with the capsule hand the same fit reaches
// only 1.6-2.0 mm vertex error and IoU 0.87-0.90 (below this test's bounds).
TEST(CeresHandFitterSilhouetteTest, NoiseFreeKeypointsAndMasks) {
  const SilhouetteScene scene;
  for (int trial = 0; trial < 2; ++trial) {
    auto [frame, input] = scene.NextTrial();
    const CeresHandFitter& fitter = scene.fitter;
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

namespace handlabel {
namespace {

// An object in front of the index and middle fingers in every view: discs over their
// two outer joints and tips, cut out of the observed hand masks. Returns the
// occluder masks and replaces `masks` by the visible hand pixels.
std::vector<MaskImage> OccludeTwoFingers(const testing::SceneFrame& frame,
                                         std::vector<MaskImage>* masks) {
  std::vector<MaskImage> occluders;
  for (size_t v = 0; v < frame.views.size(); ++v) {
    const Keypoints2d& kp = frame.views[v].keypoints;
    MaskImage occluder = MaskImage::Zero((*masks)[v].rows(), (*masks)[v].cols());
    const double radius = 0.8 * (kp.uv_px.row(8) - kp.uv_px.row(6)).norm();
    for (int k : {7, 8, 11, 12}) {
      for (Eigen::Index y = 0; y < occluder.rows(); ++y) {
        for (Eigen::Index x = 0; x < occluder.cols(); ++x) {
          const Eigen::Vector2d d(x - kp.uv_px(k, 0), y - kp.uv_px(k, 1));
          if (d.norm() <= radius) occluder(y, x) = 255;
        }
      }
    }
    for (Eigen::Index i = 0; i < occluder.size(); ++i) {
      if (occluder.data()[i] != 0) (*masks)[v].data()[i] = 0;
    }
    occluders.push_back(std::move(occluder));
  }
  return occluders;
}

double FingerError(const Points3d& a, const Points3d& b) {
  double sum = 0;
  for (int k = 5; k <= 12; ++k) sum += (a.row(k) - b.row(k)).norm();
  return sum / 8;
}

// Without the occluder masks the silhouette term pulls the hidden fingers out of the
// object's pixels; with them the fit stays at the truth.
TEST(CeresHandFitterSilhouetteTest, OccluderMasksKeepFingersBehindAnObject) {
  const SilhouetteScene scene;
  for (int trial = 0; trial < 2; ++trial) {
    auto [frame, input] = scene.NextTrial();
    const CeresHandFitter& fitter = scene.fitter;
    const std::vector<MaskImage> occluders = OccludeTwoFingers(frame, &input.masks);
    const HandParams init = fitter.InitFromViews(input.views);
    const HandFitResult unaware = fitter.Fit(input, init);
    input.occluder_masks = occluders;
    const HandFitResult aware = fitter.Fit(input, init);
    const double aware_mm = 1000 * FingerError(aware.keypoints, frame.mesh.keypoints);
    const double unaware_mm = 1000 * FingerError(unaware.keypoints, frame.mesh.keypoints);
    RecordProperty("aware_um_" + std::to_string(trial), int(1000 * aware_mm));
    RecordProperty("unaware_um_" + std::to_string(trial), int(1000 * unaware_mm));
    std::cout << "trial " << trial << ": occlusion-aware " << aware_mm << " mm, unaware "
              << unaware_mm << " mm\n";
    EXPECT_LT(aware_mm, 2.0) << trial;
    EXPECT_GT(unaware_mm, aware_mm + 0.5) << trial;
    for (double iou : aware.view_iou) EXPECT_GT(iou, 0.85) << trial;
  }
}

// The same object, but nobody masked it: with unknown_occluders the silhouettes are
// one-sided and leave the hidden fingers where the keypoints put them. The result
// also carries the keypoints-only fit the silhouette rounds started from.
TEST(CeresHandFitterSilhouetteTest, OneSidedSilhouettesWithUnknownOccluders) {
  const SilhouetteScene scene;
  for (int trial = 0; trial < 2; ++trial) {
    auto [frame, input] = scene.NextTrial();
    const CeresHandFitter& fitter = scene.fitter;
    OccludeTwoFingers(frame, &input.masks);
    input.unknown_occluders = true;
    const HandParams init = fitter.InitFromViews(input.views);
    const HandFitResult one_sided = fitter.Fit(input, init);
    const double one_sided_mm =
        1000 * FingerError(one_sided.keypoints, frame.mesh.keypoints);
    std::cout << "trial " << trial << ": one-sided " << one_sided_mm << " mm\n";
    EXPECT_LT(one_sided_mm, 2.0) << trial;
    ASSERT_TRUE(one_sided.keypoints_only.has_value());
    const HandFitStageResult& kp = *one_sided.keypoints_only;
    EXPECT_LT(MeanPointError(kp.keypoints, frame.mesh.keypoints), 0.002) << trial;
    EXPECT_EQ(kp.view_rms_px.size(), 8u);
    EXPECT_EQ(kp.view_iou.size(), 8u);
    // The keypoints-only fit is what the same fit without silhouettes gives.
    HandFitInput no_masks = input;
    no_masks.masks.clear();
    const HandFitResult plain = fitter.Fit(no_masks, init);
    EXPECT_FALSE(plain.keypoints_only.has_value());
    EXPECT_LT(MeanPointError(plain.keypoints, kp.keypoints), 1e-9) << trial;
  }
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// `mask` grown (radius > 0) or shrunk (radius < 0) by a disc of |radius| pixels.
MaskImage MorphDisc(const MaskImage& mask, int radius) {
  MaskImage out = mask;
  const uint8_t grow = radius > 0;
  const int r = std::abs(radius);
  for (Eigen::Index y = 0; y < mask.rows(); ++y) {
    for (Eigen::Index x = 0; x < mask.cols(); ++x) {
      for (int dy = -r; dy <= r && out(y, x) != grow * 255; ++dy) {
        for (int dx = -r; dx <= r; ++dx) {
          const Eigen::Index u = x + dx, v = y + dy;
          if (dx * dx + dy * dy > r * r || u < 0 || v < 0 || u >= mask.cols() ||
              v >= mask.rows() || (mask(v, u) != 0) != grow) {
            continue;
          }
          out(y, x) = grow * 255;
          break;
        }
      }
    }
  }
  return out;
}

// Masks dilated or eroded by 2 px (alternating over the views), exact keypoints: the
// fitter finds each view's margin and, with it taken out, the silhouettes pull the
// hand less off the keypoints' pose than without. An eroded outline lies inside the
// hand, where its samples match the nearest contour-band vertex rather than the rim (as
// in the silhouette term itself), so the margin found there is smaller than 2 px: it is
// the offset the term would pull by.
TEST(CeresHandFitterSilhouetteTest, MaskMarginTakesOutDilatedAndErodedMasks) {
  const SilhouetteScene scene;
  HandFitOptions off_options = SilhouetteScene::Options();
  off_options.mask_margin_max_px = 0;
  const CeresHandFitter off(scene.model, {}, off_options);
  for (int trial = 0; trial < 2; ++trial) {
    auto [frame, input] = scene.NextTrial();
    std::vector<int> radius;
    for (size_t v = 0; v < input.masks.size(); ++v) {
      radius.push_back(v % 2 == 0 ? 2 : -2);
      input.masks[v] = MorphDisc(input.masks[v], radius.back());
    }
    const HandParams init = scene.fitter.InitFromViews(input.views);
    const HandFitResult with = scene.fitter.Fit(input, init);
    const HandFitResult without = off.Fit(input, init);
    ASSERT_EQ(with.view_mask_margin_px.size(), input.masks.size());
    double eroded_sum = 0;
    for (size_t v = 0; v < input.masks.size(); ++v) {
      const double margin = with.view_mask_margin_px[v];
      if (radius[v] > 0) {
        EXPECT_NEAR(margin, 2.0, 0.75) << trial << " view " << v;
      } else {
        EXPECT_LT(margin, 0.0) << trial << " view " << v;
        eroded_sum += margin;
      }
      EXPECT_TRUE(std::isnan(without.view_mask_margin_px[v]));
    }
    EXPECT_LT(eroded_sum / 4, -0.3) << trial;
    const double with_mm = 1000 * MeanPointError(with.vertices, frame.mesh.vertices);
    const double without_mm =
        1000 * MeanPointError(without.vertices, frame.mesh.vertices);
    std::cout << "trial " << trial << ": vertex error with margin " << with_mm
              << " mm, without " << without_mm << " mm\n";
    EXPECT_LT(with_mm, 1.2) << trial;
    EXPECT_LT(with_mm, without_mm - 0.02) << trial;
  }
}

}  // namespace
}  // namespace handlabel
