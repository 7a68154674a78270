#include "hand/metrics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <vector>

#include "core/errors.h"
#include "tests/hand/lbs_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::JsonMatrix;

Points3d Pts(std::initializer_list<std::array<double, 3>> rows) {
  Points3d p(rows.size(), 3);
  int i = 0;
  for (const auto& r : rows) p.row(i++) << r[0], r[1], r[2];
  return p;
}

TEST(MetricsTest, HandComputedMeanErrors) {
  const Points3d truth = Pts({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Points3d pred = Pts({{0, 0, 3}, {1, 4, 0}, {0, 1, 0}});
  // Distances 3, 4, 0.
  EXPECT_DOUBLE_EQ(MeanPointError(pred, truth), 7.0 / 3.0);
  // Root-relative: pred - (0,0,3) = {0,0,0}, {1,4,-3}, {0,1,-3}; distances 0, 5, 3.
  EXPECT_DOUBLE_EQ(RootRelativeMeanPointError(pred, truth, pred.row(0).transpose(),
                                              truth.row(0).transpose()),
                   8.0 / 3.0);
}

TEST(MetricsTest, ProcrustesUndoesASimilarity) {
  Points3d truth(21, 3);
  for (int i = 0; i < 21; ++i) truth.row(i) = testing::RandomVector3(-0.05, 0.05);
  const Eigen::Matrix3d r = testing::RandomRotation().toRotationMatrix();
  SimilarityTransform s;
  s.scale = 1.3;
  s.rotation = r;
  s.translation = {0.1, -0.2, 0.7};
  const Points3d pred = s.Apply(truth);
  EXPECT_GT(MeanPointError(pred, truth), 0.01);
  EXPECT_LT(ProcrustesMeanPointError(pred, truth), 1e-12);
  const SimilarityTransform back = ProcrustesAlignment(pred, truth);
  EXPECT_NEAR(back.scale, 1.0 / 1.3, 1e-12);
  EXPECT_THAT(Eigen::MatrixXd(back.rotation), testing::MatrixNear(r.transpose(), 1e-12));
}

TEST(MetricsTest, ReflectionOnlyWhenAllowed) {
  Points3d truth(10, 3);
  for (int i = 0; i < 10; ++i) truth.row(i) = testing::RandomVector3(-1, 1);
  Points3d mirrored = truth;
  mirrored.col(0) *= -1.0;
  EXPECT_LT(ProcrustesMeanPointError(mirrored, truth, true), 1e-12);
  EXPECT_GT(ProcrustesMeanPointError(mirrored, truth, false), 0.1);
  const SimilarityTransform s = ProcrustesAlignment(mirrored, truth, false);
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
}

TEST(MetricsTest, PckHandComputed) {
  // Two frames, two points: errors {0, 1} and {2, 3}.
  Eigen::MatrixXd errors(2, 2);
  errors << 0, 2, 1, 3;
  EXPECT_DOUBLE_EQ(PckAt(errors, 0.5), 0.25);  // point 0: 1/2, point 1: 0/2
  EXPECT_DOUBLE_EQ(PckAt(errors, 2.0), 0.75);  // 2/2 and 1/2
  PckOptions o;
  o.min_threshold = 0.0;
  o.max_threshold = 4.0;
  o.steps = 5;  // thresholds 0, 1, 2, 3, 4 -> pck .25 .5 .75 1 1
  const PckCurve c = ComputePck(errors, o);
  ASSERT_EQ(c.pck.size(), 5u);
  EXPECT_DOUBLE_EQ(c.pck[1], 0.5);
  // Trapezoids: .375 + .625 + .875 + 1 = 2.875, / 4.
  EXPECT_DOUBLE_EQ(c.auc, 2.875 / 4.0);
}

TEST(MetricsTest, PckOptionsCheck) {
  PckOptions o;
  o.steps = 1;
  EXPECT_THROW(o.Check("test"), InputError);
  o = {};
  o.max_threshold = 0.0;
  EXPECT_THROW(o.Check("test"), InputError);
}

// Against NumPy/SciPy (tests/data/metrics/make_metrics_fixture.py, POEM's code path).
TEST(MetricsTest, MatchesNumpyScipyFixture) {
  std::ifstream in(std::string(HANDLABEL_SOURCE_DIR) +
                   "/tests/data/metrics/metrics_fixture.json");
  ASSERT_TRUE(in);
  const nlohmann::json fixture = nlohmann::json::parse(in);
  for (const auto& f : fixture["frames"]) {
    const Points3d truth = JsonMatrix(f["truth"]);
    const Points3d pred = JsonMatrix(f["pred"]);
    EXPECT_NEAR(MeanPointError(pred, truth), f["mean_error"].get<double>(), 1e-12);
    EXPECT_NEAR(RootRelativeMeanPointError(pred, truth, pred.row(0).transpose(),
                                           truth.row(0).transpose()),
                f["root_relative_error"].get<double>(), 1e-12);
    EXPECT_NEAR(ProcrustesMeanPointError(pred, truth), f["pa_error"].get<double>(),
                1e-10);
  }
  const auto& p = fixture["pck"];
  PckOptions o;
  o.min_threshold = p["min"];
  o.max_threshold = p["max"];
  o.steps = p["steps"];
  const Eigen::MatrixXd errors = JsonMatrix(p["errors"]);
  const PckCurve c = ComputePck(errors, o);
  for (int i = 0; i < o.steps; ++i)
    EXPECT_NEAR(c.pck[i], p["curve"][i].get<double>(), 1e-12);
  EXPECT_NEAR(c.auc, p["auc"].get<double>(), 1e-12);
  EXPECT_NEAR(PckAt(errors, 0.01), p["pck_at_10mm"].get<double>(), 1e-12);
}

TEST(MetricsTest, EvaluateHandFrameConsistent) {
  Points3d kp(21, 3), verts(40, 3);
  for (int i = 0; i < 21; ++i) kp.row(i) = testing::RandomVector3(-0.05, 0.05);
  for (int i = 0; i < 40; ++i) verts.row(i) = testing::RandomVector3(-0.05, 0.05);
  const Eigen::RowVector3d shift(0.002, 0, 0);
  const HandFrameMetrics m =
      EvaluateHandFrame(kp.rowwise() + shift, kp, verts.rowwise() + shift, verts);
  EXPECT_NEAR(m.mpjpe, 0.002, 1e-15);
  EXPECT_NEAR(m.mpvpe, 0.002, 1e-15);
  EXPECT_NEAR(m.rr_mpjpe, 0.0, 1e-15);
  EXPECT_NEAR(m.rr_mpvpe, 0.0, 1e-15);
  EXPECT_NEAR(m.pa_mpjpe, 0.0, 1e-12);
}

// Points moving with constant accelerations A_k: p_k(t) = p0_k + v_k t + A_k t^2 / 2, so
// every second difference is A_k exactly (up to rounding).
Points3d QuadraticTrajectoryAt(double t, const Points3d& p0, const Points3d& v,
                               const Points3d& acceleration) {
  return p0 + t * v + 0.5 * t * t * acceleration;
}

std::vector<MotionFrame> QuadraticFrames(int count, const Points3d& p0, const Points3d& v,
                                         const Points3d& truth_acc,
                                         const Points3d& predicted_acc) {
  std::vector<MotionFrame> frames;
  for (int t = 0; t < count; ++t) {
    MotionFrame f;
    f.number = 100 + t;
    f.truth = QuadraticTrajectoryAt(t, p0, v, truth_acc);
    // An offset does not accelerate: only the acceleration difference is an error.
    f.predicted = QuadraticTrajectoryAt(t, p0, v, predicted_acc).array() + 0.01;
    frames.push_back(f);
  }
  return frames;
}

TEST(MotionMetrics, QuadraticTrajectoriesHaveTheirConstantAcceleration) {
  const Points3d p0 = Pts({{0.1, 0.2, 0.3}, {-0.2, 0.0, 0.5}});
  const Points3d v = Pts({{0.01, -0.02, 0.0}, {0.0, 0.005, 0.003}});
  const Points3d truth_acc = Pts({{0.003, 0.0, 0.004}, {0.0, -0.001, 0.0}});   // 5, 1 mm
  const Points3d predicted_acc = Pts({{0.0, 0.0, 0.004}, {0.0, 0.001, 0.0}});  // 4, 1 mm
  const MotionMetrics m =
      ComputeMotionMetrics(QuadraticFrames(10, p0, v, truth_acc, predicted_acc));
  EXPECT_EQ(m.triples, 8);
  EXPECT_NEAR(m.truth_acceleration, (0.005 + 0.001) / 2, 1e-12);
  EXPECT_NEAR(m.jitter, (0.004 + 0.001) / 2, 1e-12);
  // |(0, 0, 4) - (3, 0, 4)| = 3 mm, |(0, 1, 0) - (0, -1, 0)| = 2 mm.
  EXPECT_NEAR(m.acceleration_error, (0.003 + 0.002) / 2, 1e-12);
}

TEST(MotionMetrics, AlternatingNoiseOnAStraightLineIsFourTimesItsSize) {
  // n_t = (-1)^t e: n_{t-1} - 2 n_t + n_{t+1} = 4 e in size; the line itself has no
  // acceleration.
  std::vector<MotionFrame> frames;
  for (int t = 0; t < 7; ++t) {
    MotionFrame f;
    f.number = t;
    f.truth = Pts({{0.01 * t, 0, 0}});
    f.predicted = f.truth;
    f.predicted(0, 1) += (t % 2 == 0 ? 1 : -1) * 0.002;
    frames.push_back(f);
  }
  const MotionMetrics m = ComputeMotionMetrics(frames);
  EXPECT_EQ(m.triples, 5);
  EXPECT_NEAR(m.truth_acceleration, 0, 1e-15);
  EXPECT_NEAR(m.acceleration_error, 0.008, 1e-12);
  EXPECT_NEAR(m.jitter, 0.008, 1e-12);
}

TEST(MotionMetrics, GaussianNoiseMatchesItsExpectedAcceleration) {
  // a = n1 - 2 n2 + n3 of i.i.d. N(0, s^2 I) noise is N(0, 6 s^2 I); the mean norm of
  // a 3D Gaussian of per-axis sigma r is r * 2 sqrt(2 / pi).
  const double sigma = 0.001;
  std::mt19937_64 rng(45);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<MotionFrame> frames;
  for (int t = 0; t < 2000; ++t) {
    MotionFrame f;
    f.number = t;
    f.truth = Points3d::Constant(21, 3, 0.2);
    f.predicted = f.truth;
    for (int i = 0; i < f.predicted.size(); ++i) f.predicted(i) += noise(rng);
    frames.push_back(f);
  }
  const MotionMetrics m = ComputeMotionMetrics(frames);
  const double expected = std::sqrt(6.0) * sigma * 2.0 * std::sqrt(2.0 / M_PI);
  EXPECT_NEAR(m.acceleration_error, expected, 0.02 * expected);
  EXPECT_NEAR(m.jitter, m.acceleration_error, 1e-12);  // the truth stands still
}

TEST(MotionMetrics, GapsAreNeverDifferencedAcross) {
  // Frames 0-2 and 4-6 on two unrelated straight lines, frame 3 missing: the jump
  // between them must not count, and only the two whole triples do.
  std::vector<MotionFrame> frames;
  for (int t : {0, 1, 2, 4, 5, 6}) {
    MotionFrame f;
    f.number = t;
    f.predicted = Pts({{0.001 * t + (t > 3 ? 1.0 : 0.0), 0, 0}});
    frames.push_back(f);
  }
  const MotionMetrics m = ComputeMotionMetrics(frames);
  EXPECT_EQ(m.triples, 2);
  EXPECT_NEAR(m.jitter, 0, 1e-12);
  EXPECT_EQ(m.acceleration_error, 0);  // no truth
  // Fewer than three consecutive frames: nothing to difference.
  frames.resize(2);
  EXPECT_EQ(ComputeMotionMetrics(frames).triples, 0);
  EXPECT_EQ(ComputeMotionMetrics({}).triples, 0);
}

TEST(MotionMetrics, FramesOutOfOrderAreRefused) {
  std::vector<MotionFrame> frames(3);
  for (int t = 0; t < 3; ++t) {
    frames[t].number = 2 - t;
    frames[t].predicted = Pts({{0, 0, 0}});
  }
  EXPECT_ANY_THROW(ComputeMotionMetrics(frames));
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// Bone lengths do not change with a rigid motion of the hand; stretching one bone
// shows up in its entry only, and the mean error is that stretch / 20.
TEST(BoneLengths, RigidMotionKeepsThemAndAStretchedBoneShows) {
  std::mt19937_64 rng(45);
  std::normal_distribution<double> g(0.0, 0.05);
  Points3d keypoints(kNumHandKeypoints, 3);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    keypoints.row(k) << g(rng), g(rng), g(rng);
  }
  const Eigen::Matrix3d r =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  Points3d moved =
      (keypoints * r.transpose()).rowwise() + Eigen::RowVector3d(0.1, -0.2, 0.3);
  EXPECT_LT((BoneLengths(moved) - BoneLengths(keypoints)).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(MeanBoneLengthError(moved, keypoints), 1e-12);
  // Move the index tip (keypoint 8, child of 7) 6 mm further along its bone.
  Points3d stretched = keypoints;
  const Eigen::RowVector3d bone = keypoints.row(8) - keypoints.row(7);
  stretched.row(8) += 0.006 * bone.normalized();
  const Eigen::VectorXd difference = BoneLengths(stretched) - BoneLengths(keypoints);
  EXPECT_NEAR(difference[7], 0.006, 1e-12);
  EXPECT_NEAR(difference.cwiseAbs().sum(), 0.006, 1e-12);
  EXPECT_NEAR(MeanBoneLengthError(stretched, keypoints), 0.006 / 20, 1e-12);
}

}  // namespace
}  // namespace handlabel
