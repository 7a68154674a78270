#include "geometry/camera.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MatrixNear;
using testing::Uniform;

// One realistic camera per model, 640x480, with distortion strong enough to matter
// at the corners but monotonic over the image (as real calibrated lenses are).
std::vector<Camera> CamerasOfEveryModel() {
  const int w = 640, h = 480;
  return {
      Camera(CameraModelId::kSimplePinhole, w, h, {600, 320, 240}),
      Camera(CameraModelId::kPinhole, w, h, {610, 605, 318, 244}),
      Camera(CameraModelId::kSimpleRadial, w, h, {600, 320, 240, -0.12}),
      Camera(CameraModelId::kRadial, w, h, {600, 320, 240, -0.15, 0.05}),
      Camera(CameraModelId::kOpenCV, w, h,
             {610, 605, 318, 244, -0.2, 0.08, 0.001, -0.0015}),
      Camera(CameraModelId::kOpenCVFisheye, w, h,
             {400, 400, 320, 240, 0.05, -0.02, 0.004, -0.001}),
      Camera(CameraModelId::kFullOpenCV, w, h,
             {610, 605, 318, 244, 0.3, -0.1, 0.001, -0.001, 0.02, 0.6, -0.05, 0.01}),
  };
}

TEST(Camera, ProjectUnprojectRoundTripEveryModel) {
  for (const Camera& cam : CamerasOfEveryModel()) {
    SCOPED_TRACE(CameraModelName(cam.model()));
    for (int i = 0; i < 500; ++i) {
      const Eigen::Vector2d uv(Uniform(0, cam.width() - 1), Uniform(0, cam.height() - 1));
      const double depth = Uniform(0.2, 3.0);
      const Eigen::Vector3d point = cam.Unproject(uv) * depth;
      Eigen::Vector2d back;
      ASSERT_TRUE(cam.Project(point, &back));
      EXPECT_LE((back - uv).norm(), 1e-9 * uv.norm());
      // And the other way round: a 3D point, projected then unprojected, lies on the ray.
      const Eigen::Vector3d p(Uniform(-0.4, 0.4), Uniform(-0.3, 0.3), Uniform(0.8, 2));
      Eigen::Vector2d pix;
      ASSERT_TRUE(cam.Project(p, &pix));
      if (!cam.InImage(pix)) continue;
      const Eigen::Vector3d ray = cam.Unproject(pix);
      EXPECT_LE((ray * p.z() - p).norm(), 1e-9 * p.norm());
    }
  }
}

TEST(Camera, UndistortOfDistortIsIdentityOverWholeImageIncludingCorners) {
  for (const Camera& cam : CamerasOfEveryModel()) {
    SCOPED_TRACE(CameraModelName(cam.model()));
    double worst_px = 0;
    // A dense grid that includes the four corner pixels and the borders.
    for (int v = 0; v <= 48; ++v) {
      for (int u = 0; u <= 64; ++u) {
        const Eigen::Vector2d uv(u * (cam.width() - 1) / 64.0,
                                 v * (cam.height() - 1) / 48.0);
        const Eigen::Vector2d xy_distorted((uv.x() - cam.cx()) / cam.fx(),
                                           (uv.y() - cam.cy()) / cam.fy());
        const Eigen::Vector2d xy = cam.Undistort(xy_distorted);
        const Eigen::Vector2d again = cam.Distort(xy);
        const Eigen::Vector2d err((again.x() - xy_distorted.x()) * cam.fx(),
                                  (again.y() - xy_distorted.y()) * cam.fy());
        worst_px = std::max(worst_px, err.norm());
      }
    }
    EXPECT_LE(worst_px, 1e-6);
  }
}

TEST(Camera, DistortionJacobianMatchesFiniteDifferences) {
  for (const Camera& cam : CamerasOfEveryModel()) {
    SCOPED_TRACE(CameraModelName(cam.model()));
    for (int i = 0; i < 50; ++i) {
      const Eigen::Vector2d xy(Uniform(-0.5, 0.5), Uniform(-0.4, 0.4));
      Eigen::Matrix2d jac;
      cam.Distort(xy, &jac);
      Eigen::Matrix2d numeric;
      const double h = 1e-6;
      for (int k = 0; k < 2; ++k) {
        Eigen::Vector2d d = Eigen::Vector2d::Zero();
        d[k] = h;
        numeric.col(k) = (cam.Distort(xy + d) - cam.Distort(xy - d)) / (2 * h);
      }
      EXPECT_THAT(jac, MatrixNear(numeric, 1e-7));
    }
  }
}

TEST(Camera, ProjectionJacobiansMatchFiniteDifferences) {
  for (const Camera& cam : CamerasOfEveryModel()) {
    SCOPED_TRACE(CameraModelName(cam.model()));
    for (int i = 0; i < 30; ++i) {
      const Eigen::Vector3d p(Uniform(-0.3, 0.3), Uniform(-0.2, 0.2), Uniform(0.7, 1.5));
      Eigen::Vector2d uv;
      Eigen::Matrix<double, 2, 3> d_point;
      Eigen::MatrixXd d_params;
      ASSERT_TRUE(cam.ProjectWithJacobian(p, &uv, &d_point, &d_params));
      const double h = 1e-6;
      Eigen::Matrix<double, 2, 3> numeric_point;
      for (int k = 0; k < 3; ++k) {
        Eigen::Vector3d d = Eigen::Vector3d::Zero();
        d[k] = h;
        Eigen::Vector2d plus, minus;
        cam.Project(p + d, &plus);
        cam.Project(p - d, &minus);
        numeric_point.col(k) = (plus - minus) / (2 * h);
      }
      EXPECT_THAT(d_point, MatrixNear(numeric_point, 1e-4));
      Eigen::MatrixXd numeric_params(2, cam.params().size());
      for (size_t k = 0; k < cam.params().size(); ++k) {
        Camera plus = cam, minus = cam;
        plus.mutable_params()[k] += h;
        minus.mutable_params()[k] -= h;
        Eigen::Vector2d up, um;
        plus.Project(p, &up);
        minus.Project(p, &um);
        numeric_params.col(k) = (up - um) / (2 * h);
      }
      EXPECT_THAT(d_params, MatrixNear(numeric_params, 1e-4));
    }
  }
}

TEST(Camera, PointsBehindTheCameraDoNotProject) {
  const Camera cam = Camera::Pinhole(500, 500, 320, 240, 640, 480);
  Eigen::Vector2d uv(-7, -7);
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0, 0, -1), &uv));
  EXPECT_FALSE(cam.Project(Eigen::Vector3d(0.1, 0, 0), &uv));
  EXPECT_EQ(uv, Eigen::Vector2d(-7, -7));
}

TEST(Camera, BadParametersNameTheField) {
  try {
    Camera(CameraModelId::kOpenCV, 640, 480, {500, 500, 320}, "rig.json cameras[2]");
    FAIL() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("rig.json cameras[2]"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("8 values for OPENCV"));
    EXPECT_THAT(e.what(), ::testing::HasSubstr("got 3"));
  }
  EXPECT_THROW(Camera(CameraModelId::kPinhole, 0, 480, {1, 1, 1, 1}), InputError);
  EXPECT_THROW(Camera(CameraModelId::kPinhole, 640, 480, {-1, 1, 1, 1}), InputError);
  EXPECT_THROW(CameraModelFromName("PINHOLEZ", "x"), InputError);
  EXPECT_THROW(CameraModelFromId(9, "x"), InputError);
  EXPECT_EQ(CameraModelFromName("FULL_OPENCV", "x"), CameraModelId::kFullOpenCV);
}

}  // namespace
}  // namespace handlabel
