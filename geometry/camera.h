#pragma once
// A camera's intrinsics: model, image size and parameters (COLMAP layout, see
// camera_models.h). Pixel coordinates: the centre of the top-left pixel is (0, 0)
// as in OpenCV; axes x right, y down, z forward.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "geometry/camera_models.h"

namespace handlabel {

class Camera {
 public:
  Camera() = default;
  // Throws InputError (naming `source`) if the parameter count or size is wrong.
  Camera(CameraModelId model, int width, int height, std::vector<double> params,
         const std::string& source = "camera");
  static Camera Pinhole(double fx, double fy, double cx, double cy, int width,
                        int height);

  CameraModelId model() const { return model_; }
  int width() const { return width_; }
  int height() const { return height_; }
  const std::vector<double>& params() const { return params_; }
  std::vector<double>& mutable_params() { return params_; }
  double fx() const;
  double fy() const;
  double cx() const;
  double cy() const;
  bool HasDistortion() const;

  // Pixel of a point in camera coordinates; false if it is behind the camera.
  bool Project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv) const;
  // Same, with the 2x3 Jacobian d(uv)/d(point_in_cam) and, if wanted, the
  // 2 x NumParams Jacobian d(uv)/d(params) (row-major).
  bool ProjectWithJacobian(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv,
                           Eigen::Matrix<double, 2, 3>* d_point,
                           Eigen::MatrixXd* d_params = nullptr) const;

  // Normalised (z = 1) undistorted coordinates <-> pixels.
  Eigen::Vector2d ImageFromNormalized(const Eigen::Vector2d& xy) const;
  // Inverts the distortion by Newton's method; exact to ~1e-12 inside the image.
  Eigen::Vector2d NormalizedFromImage(const Eigen::Vector2d& uv) const;
  // Unit-free ray (z = 1) through a pixel.
  Eigen::Vector3d Unproject(const Eigen::Vector2d& uv) const {
    const Eigen::Vector2d xy = NormalizedFromImage(uv);
    return Eigen::Vector3d(xy.x(), xy.y(), 1.0);
  }

  // Distortion on normalised coordinates, with the 2x2 Jacobian d(distorted)/d(xy).
  Eigen::Vector2d Distort(const Eigen::Vector2d& xy,
                          Eigen::Matrix2d* jacobian = nullptr) const;
  Eigen::Vector2d Undistort(const Eigen::Vector2d& xy_distorted) const;

  bool InImage(const Eigen::Vector2d& uv, double margin = 0) const {
    return uv.x() >= -0.5 + margin && uv.y() >= -0.5 + margin &&
           uv.x() <= width_ - 0.5 - margin && uv.y() <= height_ - 0.5 - margin;
  }

 private:
  CameraModelId model_ = CameraModelId::kPinhole;
  int width_ = 0;
  int height_ = 0;
  std::vector<double> params_;
};

}  // namespace handlabel
