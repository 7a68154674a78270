#include "geometry/camera.h"

#include <Eigen/LU>
#include <cmath>

#include "core/errors.h"
#include "geometry/dual.h"

namespace handlabel {

Camera::Camera(CameraModelId model, int width, int height, std::vector<double> params,
               const std::string& source)
    : model_(model), width_(width), height_(height), params_(std::move(params)) {
  const int expected = NumCameraParams(model);
  if (static_cast<int>(params_.size()) != expected) {
    throw InputError(source, "params",
                     std::to_string(expected) + " values for " + CameraModelName(model),
                     std::to_string(params_.size()));
  }
  if (width <= 0 || height <= 0) {
    throw InputError(source, "width/height", "positive image size",
                     std::to_string(width) + "x" + std::to_string(height));
  }
  for (double p : params_) {
    if (!std::isfinite(p))
      throw InputError(source, "params", "finite numbers", "NaN/inf");
  }
  if (fx() <= 0 || fy() <= 0) {
    throw InputError(source, "params", "positive focal lengths");
  }
}

Camera Camera::Pinhole(double fx, double fy, double cx, double cy, int width,
                       int height) {
  return Camera(CameraModelId::kPinhole, width, height, {fx, fy, cx, cy});
}

double Camera::fx() const { return UnpackIntrinsics(model_, params_.data()).fx; }
double Camera::fy() const { return UnpackIntrinsics(model_, params_.data()).fy; }
double Camera::cx() const { return UnpackIntrinsics(model_, params_.data()).cx; }
double Camera::cy() const { return UnpackIntrinsics(model_, params_.data()).cy; }

bool Camera::HasDistortion() const {
  const Intrinsics<double> in = UnpackIntrinsics(model_, params_.data());
  for (double d : in.d) {
    if (d != 0.0) return true;
  }
  return false;
}

bool Camera::Project(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv) const {
  return ProjectToImage(model_, params_.data(), point_in_cam.data(), uv->data());
}

bool Camera::ProjectWithJacobian(const Eigen::Vector3d& point_in_cam, Eigen::Vector2d* uv,
                                 Eigen::Matrix<double, 2, 3>* d_point,
                                 Eigen::MatrixXd* d_params) const {
  using D3 = Dual<3>;
  D3 p[3] = {D3(point_in_cam.x(), 0), D3(point_in_cam.y(), 1), D3(point_in_cam.z(), 2)};
  D3 params[12];
  for (size_t i = 0; i < params_.size(); ++i) params[i] = D3(params_[i]);
  D3 out[2];
  if (!ProjectToImage(model_, params, p, out)) return false;
  *uv = Eigen::Vector2d(out[0].a, out[1].a);
  if (d_point) {
    d_point->row(0) = out[0].v.transpose();
    d_point->row(1) = out[1].v.transpose();
  }
  if (d_params) {
    using D12 = Dual<12>;
    D12 q[3] = {D12(point_in_cam.x()), D12(point_in_cam.y()), D12(point_in_cam.z())};
    D12 par[12];
    for (size_t i = 0; i < params_.size(); ++i)
      par[i] = D12(params_[i], static_cast<int>(i));
    D12 o[2];
    ProjectToImage(model_, par, q, o);
    const int n = static_cast<int>(params_.size());
    d_params->resize(2, n);
    d_params->row(0) = o[0].v.head(n).transpose();
    d_params->row(1) = o[1].v.head(n).transpose();
  }
  return true;
}

Eigen::Vector2d Camera::Distort(const Eigen::Vector2d& xy,
                                Eigen::Matrix2d* jacobian) const {
  if (jacobian == nullptr) {  // the same arithmetic on values only (every projection)
    double params[12] = {};
    for (size_t i = 0; i < params_.size(); ++i) params[i] = params_[i];
    const Intrinsics<double> in = UnpackIntrinsics(model_, params);
    double xd, yd;
    DistortNormalized(in, xy.x(), xy.y(), &xd, &yd);
    return Eigen::Vector2d(xd, yd);
  }
  using D2 = Dual<2>;
  D2 params[12];
  for (size_t i = 0; i < params_.size(); ++i) params[i] = D2(params_[i]);
  const Intrinsics<D2> in = UnpackIntrinsics(model_, params);
  D2 xd, yd;
  DistortNormalized(in, D2(xy.x(), 0), D2(xy.y(), 1), &xd, &yd);
  if (jacobian) {
    jacobian->row(0) = xd.v.transpose();
    jacobian->row(1) = yd.v.transpose();
  }
  return Eigen::Vector2d(xd.a, yd.a);
}

Eigen::Vector2d Camera::Undistort(const Eigen::Vector2d& xy_distorted) const {
  if (!HasDistortion()) return xy_distorted;
  // Newton on f(x) = Distort(x) - target, started at the target itself; distortion is
  // close to identity near the centre, so this converges in a few steps.
  Eigen::Vector2d x = xy_distorted;
  for (int iter = 0; iter < 50; ++iter) {
    Eigen::Matrix2d jac;
    const Eigen::Vector2d residual = Distort(x, &jac) - xy_distorted;
    if (residual.squaredNorm() < 1e-30) break;
    const Eigen::Vector2d step = jac.partialPivLu().solve(residual);
    x -= step;
    if (step.squaredNorm() < 1e-32) break;
  }
  return x;
}

Eigen::Vector2d Camera::ImageFromNormalized(const Eigen::Vector2d& xy) const {
  const Intrinsics<double> in = UnpackIntrinsics(model_, params_.data());
  const Eigen::Vector2d d = Distort(xy);
  return Eigen::Vector2d(in.fx * d.x() + in.cx, in.fy * d.y() + in.cy);
}

Eigen::Vector2d Camera::NormalizedFromImage(const Eigen::Vector2d& uv) const {
  const Intrinsics<double> in = UnpackIntrinsics(model_, params_.data());
  return Undistort(Eigen::Vector2d((uv.x() - in.cx) / in.fx, (uv.y() - in.cy) / in.fy));
}

}  // namespace handlabel
