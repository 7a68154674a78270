// The model of where a detector puts its keypoints (hand/detector_keypoints.h) on the
// capsule hand: a known "detector" (each keypoint part-way to a skin vertex near it) is
// learned back from noisy samples with outliers, the analytic Jacobian matches central
// differences, and the file round-trips.

#include "hand/detector_keypoints.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <random>

#include "hand/capsule_hand.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_pose_sampler.h"

namespace handlabel {
namespace {

// A detector whose keypoint k lies 0.4 of the way from the model's keypoint to its
// (3 + k % 5)-th nearest vertex: a few mm off, in a different direction per keypoint.
DetectorKeypointModel KnownDetector(const HandModel& model) {
  DetectorKeypointModel known;
  known.detector = "known";
  known.learned = "test";
  known.num_vertices = model.num_vertices();
  known.vertices =
      NearestVertexIds(model, LearnDetectorKeypointsOptions().vertices_per_keypoint);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    known.weights[k].assign(known.vertices[k].size(), 0.0);
    known.weights[k][3 + k % 5] = 0.4;
  }
  return known;
}

HandParams RandomHand(const HandModel& model, std::mt19937_64& rng) {
  static const HandAnatomy anatomy = ComputeHandAnatomy(model);
  HandParams p;
  p.hand_pose = SampleHandPose(anatomy, DefaultHandLimits(), {}, rng).hand_pose;
  std::normal_distribution<double> g(0.0, 1.0);
  p.global_orient = Eigen::Vector3d(g(rng), g(rng), g(rng));
  p.betas = Eigen::VectorXd::Zero(10);
  for (int i = 0; i < 4; ++i) p.betas[i] = 0.5 * g(rng);
  p.transl = Eigen::Vector3d(0.1 * g(rng), 0.1 * g(rng), 0.5);
  return p;
}

double MeanDistance(const Points3d& a, const Points3d& b) {
  return (a - b).rowwise().norm().mean();
}

TEST(DetectorKeypoints, LearnsAKnownDetectorFromNoisySamplesWithOutliers) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const DetectorKeypointModel known = KnownDetector(model);
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.0005);  // 0.5 mm
  std::vector<DetectorKeypointSample> samples;
  for (int i = 0; i < 60; ++i) {
    DetectorKeypointSample s;
    s.truth = RandomHand(model, rng);
    s.detected = DetectorKeypointsOfMesh(known, PoseHand(model, s.truth));
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      for (int c = 0; c < 3; ++c) s.detected(k, c) += noise(rng);
      s.found[k] = (i + k) % 7 != 0;  // some keypoints not found
    }
    if (i % 10 == 0) s.detected.row(i % kNumHandKeypoints).array() += 0.03;  // wrong
    samples.push_back(s);
  }
  const DetectorKeypointModel learned =
      LearnDetectorKeypoints(model, samples, {}, "mediapipe", "test");
  EXPECT_EQ(learned.detector, "mediapipe");
  double learned_error = 0, model_error = 0;
  for (int i = 0; i < 10; ++i) {  // held-out hands
    const HandMesh mesh = PoseHand(model, RandomHand(model, rng));
    const Points3d truth = DetectorKeypointsOfMesh(known, mesh);
    learned_error += MeanDistance(DetectorKeypointsOfMesh(learned, mesh), truth) / 10;
    model_error += MeanDistance(mesh.keypoints, truth) / 10;
  }
  EXPECT_GT(model_error, 0.002);     // the known detector is millimetres off
  EXPECT_LT(learned_error, 0.0005);  // learned back within half a millimetre
}

TEST(DetectorKeypoints, JacobianMatchesCentralDifferences) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const DetectorKeypointModel known = KnownDetector(model);
  HandEvaluatorOptions options;
  options.num_betas = 10;
  const HandEvaluator evaluator(model, options);
  std::mt19937_64 rng(11);
  HandParams p = RandomHand(model, rng);
  const std::vector<int> ids = known.AllVertexIds();
  const int n = evaluator.num_params();
  std::vector<double> x(n);
  std::copy_n(p.global_orient.data(), 3, x.data());
  std::copy_n(p.hand_pose.data(), 45, x.data() + 3);
  std::copy_n(p.betas.data(), 10, x.data() + 48);
  std::copy_n(p.transl.data(), 3, x.data() + 58);
  double k[63], jacobian[63 * 61];
  DetectorKeypointsAndJacobian(evaluator, known, ids, x.data(), x.data() + 3,
                               x.data() + 48, x.data() + 58, k, jacobian);
  double templated[63];
  DetectorKeypoints(evaluator, known, ids, x.data(), x.data() + 3, x.data() + 48,
                    x.data() + 58, templated);
  const HandMesh mesh = PoseHand(model, p);
  const Points3d direct = DetectorKeypointsOfMesh(known, mesh);
  for (int i = 0; i < 63; ++i) {
    EXPECT_NEAR(k[i], templated[i], 1e-12);
    EXPECT_NEAR(k[i], direct(i / 3, i % 3), 1e-9);
  }
  double worst = 0, largest = 0;
  const double h = 1e-6;
  for (int c = 0; c < n; ++c) {
    double plus[63], minus[63];
    const double saved = x[c];
    x[c] = saved + h;
    DetectorKeypoints(evaluator, known, ids, x.data(), x.data() + 3, x.data() + 48,
                      x.data() + 58, plus);
    x[c] = saved - h;
    DetectorKeypoints(evaluator, known, ids, x.data(), x.data() + 3, x.data() + 48,
                      x.data() + 58, minus);
    x[c] = saved;
    for (int r = 0; r < 63; ++r) {
      worst =
          std::max(worst, std::abs((plus[r] - minus[r]) / (2 * h) - jacobian[r * n + c]));
      largest = std::max(largest, std::abs(jacobian[r * n + c]));
    }
  }
  EXPECT_GT(largest, 0.01);
  EXPECT_LT(worst, 1e-6);
}

TEST(DetectorKeypoints, FileRoundTripsAndChecksTheTopology) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const DetectorKeypointModel known = KnownDetector(model);
  const std::string path =
      (std::filesystem::temp_directory_path() / "detector_keypoints_test.json").string();
  WriteDetectorKeypointModel(path, known);
  const DetectorKeypointModel read = ReadDetectorKeypointModel(path);
  EXPECT_EQ(read.vertices, known.vertices);
  EXPECT_EQ(read.weights, known.weights);
  EXPECT_EQ(read.learned, "test");
  EXPECT_THROW(read.Check("model", model.num_vertices() + 1), InputError);
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace handlabel
