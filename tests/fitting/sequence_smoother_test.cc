// The sequence smoother (fitting/sequence_smoother.h) and its acceleration prior
// (fitting/acceleration_cost.h) on a smoothly moving capsule hand seen by the
// DexYCB-like rig: the prior's Jacobian against central differences, one shape for the
// window, and smoothing of noisy per-frame fits: the acceleration error falls several
// fold while MPJPE does not rise.

#include "fitting/sequence_smoother.h"

#include <gtest/gtest.h>

#include <memory>
#include <random>

#include "fitting/acceleration_cost.h"
#include "hand/capsule_hand.h"
#include "hand/metrics.h"
#include "tests/fitting/fitting_scene.h"

namespace handlabel {
namespace {

using testing::CorruptViews;
using testing::DexYcbLikeRig;

// A hand turning, sliding and closing its fingers along smooth curves (1-2 s periods
// at 30 frames/s), its 2D keypoints exact in every view.
struct MovingHand {
  std::vector<HandParams> params;
  std::vector<Points3d> keypoints;
  std::vector<std::vector<KeypointView>> views;
};

MovingHand MakeMovingHand(const HandModel& model, int frames) {
  MovingHand m;
  Eigen::VectorXd betas(10);
  betas << 0.8, -0.5, 0.3, 0.0, 0.4, -0.2, 0.1, 0.0, -0.3, 0.2;
  for (int f = 0; f < frames; ++f) {
    const double t = f / 30.0;
    HandParams p;
    p.betas = betas;
    p.global_orient =
        Eigen::Vector3d(0.3 + 0.4 * std::sin(2.1 * t), 1.2, 0.2 * std::cos(3.0 * t));
    for (int j = 0; j < 15; ++j) {
      // Bend every finger joint about its local z axis, half closed on average.
      p.hand_pose[3 * j + 2] = 0.35 + 0.3 * std::sin(3.5 * t + 0.4 * j);
    }
    p.transl = Eigen::Vector3d(0.05 * std::sin(2.5 * t), 0.03 * std::cos(1.8 * t),
                               0.02 * std::sin(4.0 * t));
    const HandMesh mesh = PoseHand(model, p);
    std::vector<KeypointView> views;
    for (const RigCamera& cam : DexYcbLikeRig()) {
      KeypointView view;
      view.camera = cam;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        Eigen::Vector2d uv;
        const bool ok = cam.ProjectWorld(mesh.keypoints.row(k).transpose(), &uv);
        view.keypoints.uv_px.row(k) = uv.transpose();
        view.keypoints.confidence[k] = ok ? 1.0 : 0.0;
      }
      views.push_back(view);
    }
    m.params.push_back(p);
    m.keypoints.push_back(mesh.keypoints);
    m.views.push_back(views);
  }
  return m;
}

std::vector<MotionFrame> Motion(const std::vector<Points3d>& predicted,
                                const std::vector<Points3d>& truth) {
  std::vector<MotionFrame> frames;
  for (size_t f = 0; f < predicted.size(); ++f) {
    frames.push_back({static_cast<int64_t>(f), predicted[f], truth[f]});
  }
  return frames;
}

double Mpjpe(const std::vector<Points3d>& predicted, const std::vector<Points3d>& truth) {
  double sum = 0;
  for (size_t f = 0; f < predicted.size(); ++f)
    sum += MeanPointError(predicted[f], truth[f]);
  return sum / predicted.size();
}

TEST(KeypointAccelerationCost, JacobianMatchesCentralDifferences) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  HandEvaluatorOptions options;
  options.num_betas = 10;
  const HandEvaluator evaluator(model, options);
  const MovingHand hand = MakeMovingHand(model, 3);
  const KeypointAccelerationCost cost(evaluator, hand.params[0].betas, 0.001);
  std::vector<std::vector<double>> blocks;
  for (const HandParams& p : hand.params) {
    blocks.push_back({p.global_orient.data(), p.global_orient.data() + 3});
    blocks.push_back({p.hand_pose.data(), p.hand_pose.data() + 45});
    blocks.push_back({p.transl.data(), p.transl.data() + 3});
  }
  std::vector<const double*> parameters;
  for (const auto& b : blocks) parameters.push_back(b.data());
  const int rows = 3 * kNumHandKeypoints;
  std::vector<double> residuals(rows);
  std::vector<std::vector<double>> jacobians(blocks.size());
  std::vector<double*> jacobian_ptrs;
  for (size_t b = 0; b < blocks.size(); ++b) {
    jacobians[b].resize(rows * blocks[b].size());
    jacobian_ptrs.push_back(jacobians[b].data());
  }
  ASSERT_TRUE(cost.Evaluate(parameters.data(), residuals.data(), jacobian_ptrs.data()));
  const double h = 1e-6;
  double worst = 0, largest = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (size_t c = 0; c < blocks[b].size(); ++c) {
      std::vector<double> plus(rows), minus(rows);
      const double x = blocks[b][c];
      blocks[b][c] = x + h;
      cost.Evaluate(parameters.data(), plus.data(), nullptr);
      blocks[b][c] = x - h;
      cost.Evaluate(parameters.data(), minus.data(), nullptr);
      blocks[b][c] = x;
      for (int r = 0; r < rows; ++r) {
        const double numeric = (plus[r] - minus[r]) / (2 * h);
        const double analytic = jacobians[b][r * blocks[b].size() + c];
        worst = std::max(worst, std::abs(numeric - analytic));
        largest = std::max(largest, std::abs(analytic));
      }
    }
  }
  EXPECT_GT(largest, 1.0);  // the test compares something
  EXPECT_LT(worst, 1e-4 * largest);
  // The residual is the keypoints' second difference per sigma.
  const Eigen::Map<const Eigen::VectorXd> r(residuals.data(), rows);
  Eigen::VectorXd expected(rows);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    for (int c = 0; c < 3; ++c) {
      expected[3 * k + c] = (hand.keypoints[0](k, c) - 2 * hand.keypoints[1](k, c) +
                             hand.keypoints[2](k, c)) /
                            0.001;
    }
  }
  EXPECT_LT((r - expected).cwiseAbs().maxCoeff(), 1e-9);
}

class SequenceSmootherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    truth_ = MakeMovingHand(model_, 40);
    std::mt19937_64 rng(45);
    const CeresHandFitter fitter(model_);
    for (size_t f = 0; f < truth_.views.size(); ++f) {
      std::vector<KeypointView> views = truth_.views[f];
      CorruptViews(&views, 4.0, 0.0, {}, rng);
      HandFitInput input;
      input.views = views;
      const HandFitResult fit = fitter.Fit(input, fitter.InitFromViews(views));
      noisy_views_.push_back(views);
      per_frame_.push_back(fit.params);
      per_frame_keypoints_.push_back(fit.keypoints);
    }
  }

  HandModel model_ = MakeCapsuleHand(HandSide::kRight);
  MovingHand truth_;
  std::vector<std::vector<KeypointView>> noisy_views_;
  std::vector<HandParams> per_frame_;
  std::vector<Points3d> per_frame_keypoints_;
};

TEST_F(SequenceSmootherTest, SequenceShapeKeepsTheTruthsBoneLengths) {
  const SequenceSmoother smoother(model_, {}, {}, {});
  const Eigen::VectorXd betas = smoother.SequenceShape(per_frame_keypoints_, per_frame_);
  HandParams shaped = truth_.params[0];
  shaped.betas = betas;
  const double error =
      MeanBoneLengthError(PoseHand(model_, shaped).keypoints, truth_.keypoints[0]);
  double per_frame_error = 0;
  for (size_t f = 0; f < per_frame_keypoints_.size(); ++f) {
    per_frame_error += MeanBoneLengthError(per_frame_keypoints_[f], truth_.keypoints[f]);
  }
  per_frame_error /= per_frame_keypoints_.size();
  EXPECT_LT(error, 0.001);  // within 1 mm
  EXPECT_LT(error, per_frame_error);
}

TEST_F(SequenceSmootherTest, SmoothingLowersAccelerationErrorWithoutRaisingMpjpe) {
  const SequenceSmoother smoother(model_, {}, {}, {});
  const Eigen::VectorXd betas = smoother.SequenceShape(per_frame_keypoints_, per_frame_);
  std::vector<SmoothFrame> frames;
  for (size_t f = 0; f < per_frame_.size(); ++f) {
    frames.push_back({noisy_views_[f], per_frame_[f]});
  }
  const SmoothWindowResult result = smoother.SmoothWindow(frames, betas);
  ASSERT_EQ(result.params.size(), frames.size());
  std::vector<Points3d> smoothed;
  for (const HandParams& p : result.params) {
    EXPECT_EQ(p.betas, betas);  // one shape through the window
    smoothed.push_back(PoseHand(model_, p).keypoints);
  }
  const MotionMetrics before =
      ComputeMotionMetrics(Motion(per_frame_keypoints_, truth_.keypoints));
  const MotionMetrics after = ComputeMotionMetrics(Motion(smoothed, truth_.keypoints));
  EXPECT_LT(after.acceleration_error, before.acceleration_error / 3)
      << before.acceleration_error << " -> " << after.acceleration_error;
  EXPECT_LE(Mpjpe(smoothed, truth_.keypoints),
            Mpjpe(per_frame_keypoints_, truth_.keypoints) + 1e-5);
  EXPECT_LT(result.final_cost, result.initial_cost);
}

TEST_F(SequenceSmootherTest, SameBitsTwice) {
  const SequenceSmoother smoother(model_, {}, {}, {});
  std::vector<SmoothFrame> frames;
  for (size_t f = 0; f < 12; ++f) frames.push_back({noisy_views_[f], per_frame_[f]});
  const Eigen::VectorXd betas = truth_.params[0].betas;
  const SmoothWindowResult a = smoother.SmoothWindow(frames, betas);
  const SmoothWindowResult b = smoother.SmoothWindow(frames, betas);
  for (size_t f = 0; f < frames.size(); ++f) {
    EXPECT_EQ(a.params[f].hand_pose, b.params[f].hand_pose);
    EXPECT_EQ(a.params[f].transl, b.params[f].transl);
  }
}

// A detector whose keypoints are not the model's: each is a skin vertex near the
// model's keypoint (a different one per keypoint, a few mm off), as MediaPipe's lie on
// the skin and elsewhere along the bones.
DetectorKeypointModel OffsetDetector(const HandModel& model) {
  DetectorKeypointModel d;
  d.detector = "offset";
  d.num_vertices = model.num_vertices();
  d.vertices = NearestVertexIds(model, 12);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    d.weights[k].assign(d.vertices[k].size(), 0.0);
    d.weights[k][3 + k % 5] = 1.0;
  }
  return d;
}

// Frame f of `hand` as `detector` sees it: its keypoints of the posed hand projected
// into every view, with noise_px of noise.
std::vector<KeypointView> ViewsThroughDetector(const DetectorKeypointModel& detector,
                                               const HandModel& model,
                                               const MovingHand& hand, size_t f,
                                               double noise_px, std::mt19937_64& rng) {
  const Points3d seen =
      DetectorKeypointsOfMesh(detector, PoseHand(model, hand.params[f]));
  std::vector<KeypointView> views = hand.views[f];
  for (KeypointView& view : views) {
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      Eigen::Vector2d uv;
      view.camera.ProjectWorld(seen.row(k).transpose(), &uv);
      view.keypoints.uv_px.row(k) = uv.transpose();
    }
  }
  CorruptViews(&views, noise_px, 0.0, {}, rng);
  return views;
}

// The per-frame fits of the model's keypoints to such a detector's 2D (2 px noise) have
// the detector's bones, and so has a shape from their medians or from the evidence
// without the detector's model; with it, the shape fitted to the evidence of the frames
// has the hand's own bones.
TEST(SequenceShapeFromEvidence, RecoversTheBonesOfAHandSeenThroughAnOffsetDetector) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const DetectorKeypointModel detector = OffsetDetector(model);
  MovingHand hand = MakeMovingHand(model, 8);
  std::mt19937_64 rng(46);
  const CeresHandFitter fitter(model);
  std::vector<SmoothFrame> frames;
  std::vector<Points3d> per_frame_keypoints;
  std::vector<HandParams> per_frame;
  for (size_t f = 0; f < hand.params.size(); ++f) {
    const std::vector<KeypointView> views =
        ViewsThroughDetector(detector, model, hand, f, 2.0, rng);
    HandFitInput input;
    input.views = views;
    const HandFitResult fit = fitter.Fit(input, fitter.InitFromViews(views));
    frames.push_back({views, fit.params});
    per_frame.push_back(fit.params);
    per_frame_keypoints.push_back(fit.keypoints);
  }
  const auto bone_error = [&](const Eigen::VectorXd& betas) {
    HandParams shaped = hand.params[0];
    shaped.betas = betas;
    return MeanBoneLengthError(PoseHand(model, shaped).keypoints, hand.keypoints[0]);
  };
  const SequenceSmoother plain(model, {}, {}, {});
  const SequenceSmoother with_model(model, {}, {}, {}, detector);
  const double from_medians =
      bone_error(plain.SequenceShape(per_frame_keypoints, per_frame));
  const double without_model = bone_error(plain.SequenceShapeFromEvidence(frames));
  const double with = bone_error(with_model.SequenceShapeFromEvidence(frames));
  EXPECT_GT(from_medians, 0.0015) << "the detector's offsets must bias the bones";
  EXPECT_GT(without_model, 0.0015);
  EXPECT_LT(with, 0.001) << "medians " << from_medians << ", evidence " << without_model;
}

// The per-frame fit with the detector's model (HandFitOptions::detector_keypoints, job
// field fit.detector_keypoints): fitting the model's own keypoints to such a detector's
// 2D puts the labels' joints where the detector marks them, a few mm off; comparing
// the detector's keypoints of the hand with the 2D puts them on the hand's joints.
TEST(PerFrameFit, WithTheDetectorsModelTheJointsAreTheHands) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  auto detector = std::make_shared<const DetectorKeypointModel>(OffsetDetector(model));
  MovingHand hand = MakeMovingHand(model, 4);
  std::mt19937_64 rng(47);
  HandFitOptions with_model;
  with_model.detector_keypoints = detector;
  const CeresHandFitter plain(model), aware(model, {}, with_model);
  double error_plain = 0, error_aware = 0;
  for (size_t f = 0; f < hand.params.size(); ++f) {
    const std::vector<KeypointView> views =
        ViewsThroughDetector(*detector, model, hand, f, 1.0, rng);
    HandFitInput input;
    input.views = views;
    error_plain += Mpjpe({plain.Fit(input, plain.InitFromViews(views)).keypoints},
                         {hand.keypoints[f]});
    error_aware += Mpjpe({aware.Fit(input, aware.InitFromViews(views)).keypoints},
                         {hand.keypoints[f]});
  }
  error_plain /= hand.params.size();
  error_aware /= hand.params.size();
  EXPECT_GT(error_plain, 0.002) << "the detector's offsets must move the joints";
  EXPECT_LT(error_aware, error_plain / 3) << error_plain;
}

TEST(SequenceSmoothOptions, ChecksNameTheField) {
  SequenceSmoothOptions o;
  o.acceleration_sigma_mm = 0;
  EXPECT_THROW(
      {
        try {
          o.Check("test");
        } catch (const std::exception& e) {
          EXPECT_NE(std::string(e.what()).find("acceleration_sigma_mm"),
                    std::string::npos);
          throw;
        }
      },
      std::exception);
}

}  // namespace
}  // namespace handlabel
