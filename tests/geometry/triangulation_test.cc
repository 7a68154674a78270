#include "geometry/triangulation.h"

#include "core/errors.h"

#include <gtest/gtest.h>

#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::Gaussian;
using testing::MatrixNear;
using testing::RandomVector3;

// Eight distorted 640x480 cameras on a ring about 0.8 m around the origin.
Rig EightCameraRig() {
  Rig rig;
  for (int i = 0; i < 8; ++i) {
    const double a = 2 * M_PI * i / 8;
    const Eigen::Vector3d eye(0.8 * std::cos(a), 0.3 * std::sin(3 * a),
                              0.8 * std::sin(a));
    rig.Add({"cam" + std::to_string(i),
             Camera(CameraModelId::kOpenCV, 640, 480,
                    {600.0 + 10 * i, 600.0 + 10 * i, 320, 240, -0.1, 0.02, 0.001, 0}),
             LookAt(eye, Eigen::Vector3d::Zero(), Eigen::Vector3d(0, -1, 0))});
  }
  return rig;
}

std::vector<ViewObservation> Observe(const Rig& rig, const Eigen::Vector3d& point,
                                     double noise_px) {
  std::vector<ViewObservation> obs;
  for (size_t i = 0; i < rig.size(); ++i) {
    Eigen::Vector2d uv;
    EXPECT_TRUE(rig[i].ProjectWorld(point, &uv));
    obs.push_back({static_cast<int>(i),
                   uv + Eigen::Vector2d(Gaussian(noise_px), Gaussian(noise_px)), 1.0});
  }
  return obs;
}

TEST(Triangulation, ExactForNoiseFreeViews) {
  const Rig rig = EightCameraRig();
  for (int i = 0; i < 100; ++i) {
    const Eigen::Vector3d point = RandomVector3(-0.15, 0.15);
    const auto result = TriangulateWeighted(rig, Observe(rig, point, 0.0));
    ASSERT_TRUE(result.has_value());
    EXPECT_THAT(*result, MatrixNear(point, 1e-9));
  }
}

TEST(Triangulation, ErrorGrowsSmoothlyWithNoise) {
  const Rig rig = EightCameraRig();
  std::vector<double> mean_error;
  for (double sigma : {0.5, 1.0, 2.0, 4.0}) {
    double sum = 0;
    const int n = 400;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d point = RandomVector3(-0.15, 0.15);
      sum += (*TriangulateWeighted(rig, Observe(rig, point, sigma)) - point).norm();
    }
    mean_error.push_back(sum / n);
  }
  // Linear in the noise for small noise: doubling sigma roughly doubles the error.
  for (size_t k = 1; k < mean_error.size(); ++k) {
    const double ratio = mean_error[k] / mean_error[k - 1];
    EXPECT_GT(ratio, 1.6) << "sigma step " << k;
    EXPECT_LT(ratio, 2.4) << "sigma step " << k;
  }
  // 1 px of noise with 8 views ~0.8 m away: well under a millimetre.
  EXPECT_LT(mean_error[1], 1e-3);
}

TEST(Triangulation, ConfidenceWeightsDownweightABadView) {
  const Rig rig = EightCameraRig();
  const Eigen::Vector3d point(0.02, -0.03, 0.05);
  auto obs = Observe(rig, point, 0.0);
  obs[3].uv_px += Eigen::Vector2d(30, -20);
  const double plain = (*TriangulateWeighted(rig, obs) - point).norm();
  obs[3].confidence = 0.01;
  const double weighted = (*TriangulateWeighted(rig, obs) - point).norm();
  EXPECT_LT(weighted, 0.05 * plain);
  obs[3].confidence = 0.0;
  EXPECT_THAT(*TriangulateWeighted(rig, obs), MatrixNear(point, 1e-9));
}

TEST(Triangulation, RansacIgnoresA50PixelOutlierView) {
  const Rig rig = EightCameraRig();
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d point = RandomVector3(-0.1, 0.1);
    auto obs = Observe(rig, point, 0.5);
    const int bad = trial % 8;
    obs[bad].uv_px += Eigen::Vector2d(50, 0);
    const RobustTriangulation robust = TriangulateRobust(rig, obs);
    ASSERT_TRUE(robust.valid);
    EXPECT_EQ(std::count(robust.inliers.begin(), robust.inliers.end(), bad), 0);
    EXPECT_EQ(robust.inliers.size(), 7u);
    obs[bad].confidence = 0;
    const Eigen::Vector3d without_outlier = *TriangulateWeighted(rig, obs);
    EXPECT_THAT(robust.point, MatrixNear(without_outlier, 1e-9));
  }
}

TEST(Triangulation, TooFewViewsGiveNoPoint) {
  const Rig rig = EightCameraRig();
  auto obs = Observe(rig, Eigen::Vector3d::Zero(), 0.0);
  obs.resize(1);
  EXPECT_FALSE(TriangulateWeighted(rig, obs).has_value());
  EXPECT_FALSE(TriangulateRobust(rig, obs).valid);
  RobustTriangulationOptions bad;
  bad.inlier_threshold_px = -1;
  EXPECT_THROW(bad.Check("test"), InputError);
}

}  // namespace
}  // namespace handlabel
