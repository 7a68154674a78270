// Acceptance of issue 5 on the shipped open hand (models/open_hand_right.npz) with the
// DexYCB-like rig of fitting_scene.h: noise-free keypoints + masks, noisy keypoints with
// outliers and occluded views (robust vs plain least squares), joint limits, and that
// silhouettes help noisy keypoints. The enabled tests use 1-2 frames at half
// resolution to stay fast; the 50-frame report
// runs with
//   build/tests/fitting_tests --gtest_also_run_disabled_tests
//       --gtest_filter='FittingAcceptance.DISABLED_*'
// and prints the numbers written in docs/fitting.md.

#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>

#include "fitting/ceres_hand_fitter.h"
#include "fitting/silhouette_render.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_model_io.h"
#include "hand/metrics.h"
#include "tests/fitting/fitting_scene.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

const HandModel& OpenHand() {
  static const HandModel model =
      LoadHandModel(std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz");
  return model;
}

std::vector<PixelRays> RigRays(double image_scale) {
  std::vector<PixelRays> r;
  for (const RigCamera& cam : testing::DexYcbLikeRig(image_scale))
    r.emplace_back(cam.camera);
  return r;
}

struct Totals {
  int frames = 0;
  double mpjpe = 0, mpvpe = 0, pa_mpjpe = 0, seconds = 0, worst_limit_deg = 0;
  double plain_mpjpe = 0, worst_mpjpe = 0;
  void Print(const char* name) const {
    std::printf(
        "%s: %d frames, MPJPE %.3f mm (worst frame %.3f), MPVPE %.3f mm, PA-MPJPE %.3f "
        "mm, "
        "%.3f s/frame, worst limit violation %.2f deg, plain least squares MPJPE %.3f "
        "mm\n",
        name, frames, 1000 * mpjpe / frames, 1000 * worst_mpjpe, 1000 * mpvpe / frames,
        1000 * pa_mpjpe / frames, seconds / frames, worst_limit_deg,
        1000 * plain_mpjpe / frames);
  }
};

// Objects in the scene: none, a ball held against the fingers with its occluder masks
// given to the fitter, the same ball with occluders unknown (HandFitInput::
// unknown_occluders: one-sided silhouettes), or unknown and ignored (the two-sided term
// as on empty hands).
enum class Objects { kNone, kMasked, kUnknown, kIgnored };

// noisy = false: exact keypoints and masks. true: 2 px noise, 10 % outliers, one or
// two views without keypoints or masks (alternating), masks kept for the others.
// With objects, keypoints behind the ball get 6 px more noise and confidence 0.3
// (testing::HoldBall) and the masks show the visible hand only.
// image_scale 0.5 (320x240 images) keeps the enabled tests fast.
Totals RunScenario(int frames, bool noisy, bool silhouettes, uint64_t seed,
                   double image_scale = 1.0, Objects objects = Objects::kNone) {
  const std::vector<PixelRays> rays = RigRays(image_scale);
  const HandModel& model = OpenHand();
  HandFitOptions options;
  if (!silhouettes) options.silhouette_rounds = 0;
  const CeresHandFitter fitter(model, {}, options);
  HandFitOptions plain_options = options;
  plain_options.keypoint_loss.type = RobustLossType::kTrivial;
  const CeresHandFitter plain(model, {}, plain_options);
  const HandAnatomy anatomy = ComputeHandAnatomy(model);
  std::mt19937_64 rng(seed);
  Totals t;
  for (int f = 0; f < frames; ++f) {
    testing::SceneFrame frame = testing::RandomSceneFrame(model, rng, 0.8, image_scale);
    HandFitInput input;
    if (objects == Objects::kNone) {
      for (size_t v = 0; v < frame.views.size(); ++v) {
        input.masks.push_back(RenderHandMask(frame.mesh.vertices, model.faces,
                                             frame.views[v].camera, rays[v]));
      }
    } else {
      testing::HeldBall ball = testing::HoldBall(model, &frame, rays, 6.0, rng);
      input.masks = std::move(ball.hand_masks);
      if (objects == Objects::kMasked) input.occluder_masks = ball.occluder_masks;
      input.unknown_occluders = objects == Objects::kUnknown;
    }
    if (noisy) {
      const std::vector<int> occluded =
          f % 2 == 0 ? std::vector<int>{f % 8} : std::vector<int>{f % 8, (f + 3) % 8};
      testing::CorruptViews(&frame.views, 2.0, 0.1, occluded, rng);
      for (int v : occluded) input.masks[v] = MaskImage();
    }
    if (!silhouettes) input.masks.clear();
    input.views = frame.views;
    const auto start = std::chrono::steady_clock::now();
    const HandFitResult r = fitter.Fit(input, fitter.InitFromViews(input.views));
    t.seconds +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const HandFrameMetrics m = EvaluateHandFrame(r.keypoints, frame.mesh.keypoints,
                                                 r.vertices, frame.mesh.vertices);
    t.mpjpe += m.mpjpe;
    t.mpvpe += m.mpvpe;
    t.pa_mpjpe += m.pa_mpjpe;
    t.worst_mpjpe = std::max(t.worst_mpjpe, m.mpjpe);
    HandPoseVector angles;
    HandAnatomicalAngles(anatomy, r.params.hand_pose.data(), angles.data());
    t.worst_limit_deg =
        std::max(t.worst_limit_deg, MaxLimitViolationDeg(DefaultHandLimits(), angles));
    if (noisy) {
      const HandFitResult p = plain.Fit(input, plain.InitFromViews(input.views));
      t.plain_mpjpe += MeanPointError(p.keypoints, frame.mesh.keypoints);
    }
    ++t.frames;
  }
  return t;
}

TEST(FittingAcceptance, NoiseFreeKeypointsAndMasks) {
  const Totals t = RunScenario(1, false, true, 1, 0.5);
  t.Print("noise-free kp+masks");
  EXPECT_LE(t.mpjpe / t.frames, 0.001);
  EXPECT_LE(t.mpvpe / t.frames, 0.0015);
}

TEST(FittingAcceptance, NoisyOutliersOccludedViews) {
  const Totals t = RunScenario(1, true, false, 2, 0.5);
  t.Print("noisy kp only");
  EXPECT_LE(t.mpjpe / t.frames, 0.006);
  EXPECT_LT(t.mpjpe, t.plain_mpjpe);
  EXPECT_LE(t.worst_limit_deg, 5.0);
}

// Where noisy keypoints leave the mesh loose, the silhouettes must pull it in (the
// 50-frame report: MPVPE 2.05 -> 1.47 mm); same frames, same noise, same start.
TEST(FittingAcceptance, SilhouettesImproveNoisyKeypoints) {
  const Totals with = RunScenario(2, true, true, 11, 0.5);
  with.Print("noisy kp+masks");
  const Totals without = RunScenario(2, true, false, 11, 0.5);
  without.Print("noisy kp only");
  EXPECT_LT(with.mpvpe, 0.9 * without.mpvpe);
}

// Hands holding a ball (noisy keypoints, outliers, occluded views as above): with the
// ball's occluder masks the silhouettes must not make the fit worse than keypoints
// alone; ignoring the ball (two-sided silhouettes on the carved masks) does.
TEST(FittingAcceptance, HeldBallWithOccluderMasks) {
  const Totals masked = RunScenario(2, true, true, 21, 0.5, Objects::kMasked);
  masked.Print("ball, kp+masks+occluder masks");
  const Totals kp = RunScenario(2, true, false, 21, 0.5, Objects::kMasked);
  kp.Print("ball, kp only");
  const Totals ignored = RunScenario(2, true, true, 21, 0.5, Objects::kIgnored);
  ignored.Print("ball, kp+masks, ball ignored");
  EXPECT_LE(masked.mpjpe / masked.frames, 0.006);
  EXPECT_LE(masked.mpjpe, 1.02 * kp.mpjpe);
  EXPECT_GT(ignored.mpjpe, masked.mpjpe);
}

TEST(FittingAcceptance, DISABLED_FiftyFramesHoldingABall) {
  for (Objects o : {Objects::kMasked, Objects::kUnknown, Objects::kIgnored}) {
    const char* names[] = {"", "ball, kp+masks+occluder masks", "ball, one-sided",
                           "ball, ball ignored"};
    RunScenario(50, true, true, 12, 1.0, o).Print(names[static_cast<int>(o)]);
  }
  RunScenario(50, true, false, 12, 1.0, Objects::kMasked).Print("ball, kp only");
  RunScenario(50, false, true, 12, 1.0, Objects::kMasked)
      .Print("ball, exact kp+masks+occluder masks");
}

TEST(FittingAcceptance, DISABLED_FiftyFrames) {
  const Totals exact = RunScenario(50, false, true, 10);
  exact.Print("noise-free kp+masks");
  const Totals exact_kp = RunScenario(50, false, false, 10);
  exact_kp.Print("noise-free kp only");
  const Totals noisy = RunScenario(50, true, true, 11);
  noisy.Print("noisy kp+masks");
  const Totals noisy_kp = RunScenario(50, true, false, 11);
  noisy_kp.Print("noisy kp only");
  EXPECT_LE(exact.mpjpe / exact.frames, 0.001);
  EXPECT_LE(exact.mpvpe / exact.frames, 0.0015);
  EXPECT_LE(noisy.mpjpe / noisy.frames, 0.006);
  EXPECT_LT(noisy.mpjpe, noisy.plain_mpjpe);
  EXPECT_LE(noisy.worst_limit_deg, 5.0);
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// Pose as PCA coefficients (the open hand has a 45-component basis): with all 45
// components the fit is as exact as with axis-angle; with 12 it still lands close.
TEST(FittingPca, KeypointsOnlyWithPcaPose) {
  std::mt19937_64 rng(21);
  const testing::SceneFrame frame = testing::RandomSceneFrame(OpenHand(), rng, 0.8, 0.5);
  HandFitInput input;
  input.views = frame.views;
  for (int comps : {45, 12}) {
    HandFitConfig config;
    config.pose_pca_comps = comps;
    const CeresHandFitter fitter(OpenHand(), config);
    const HandFitResult r = fitter.Fit(input, fitter.InitFromViews(input.views));
    const double error = MeanPointError(r.keypoints, frame.mesh.keypoints);
    EXPECT_LT(error, comps == 45 ? 0.001 : 0.01) << comps;
  }
}

// Temporal term, with keypoints in two views only (the loosest fit that still starts
// well), from the same start: a previous frame that is right (here the truth) makes
// the fit better, and one 20 mm off along camera 0's axis pulls the answer towards
// itself, by little: 42 keypoints at sigma 1 px outweigh a 20 mm translation sigma
// (measured: 2.75 -> 2.56 mm, pull 0.18 mm).
TEST(FittingTemporal, PreviousFramePullsALooseFit) {
  std::mt19937_64 rng(22);
  testing::SceneFrame frame = testing::RandomSceneFrame(OpenHand(), rng, 0.8, 0.5);
  testing::CorruptViews(&frame.views, 2.0, 0.0, {2, 3, 4, 5, 6, 7}, rng);
  const CeresHandFitter fitter(OpenHand());
  HandFitInput input;
  input.views = frame.views;
  const HandParams start = fitter.InitFromViews(input.views);
  const HandFitResult alone = fitter.Fit(input, start);
  EXPECT_FALSE(alone.term_costs.count("temporal"));
  const double alone_error = MeanPointError(alone.keypoints, frame.mesh.keypoints);

  input.previous = frame.params;
  const HandFitResult right = fitter.Fit(input, start);
  EXPECT_TRUE(right.term_costs.count("temporal"));
  const double right_error = MeanPointError(right.keypoints, frame.mesh.keypoints);
  RecordProperty("alone_um", static_cast<int>(1e6 * alone_error));
  RecordProperty("with_previous_um", static_cast<int>(1e6 * right_error));
  std::printf("temporal: alone %.3f mm, with the true previous %.3f mm\n",
              1e3 * alone_error, 1e3 * right_error);
  EXPECT_LT(right_error, 0.97 * alone_error);

  const Eigen::Vector3d axis =
      frame.views[0].camera.cam_from_world.rotation.inverse() * Eigen::Vector3d::UnitZ();
  HandParams off = frame.params;
  off.transl += 0.02 * axis;  // one temporal sigma
  input.previous = off;
  const HandFitResult pulled = fitter.Fit(input, start);
  const double shift = (pulled.params.transl - right.params.transl).dot(axis);
  std::printf("temporal: a previous frame 20 mm off pulls the answer %.3f mm\n",
              1e3 * shift);
  EXPECT_GT(shift, 0.00005);  // towards it: a term of no weight, or reversed, fails
  EXPECT_LT(shift, 0.002);    // and the keypoints still decide
}

}  // namespace
}  // namespace handlabel
