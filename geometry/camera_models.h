#pragma once
// Camera models, numbered and parameterised as COLMAP does (ids 0-6) so rig files
// convert without loss. All functions are templated on the scalar type so that Ceres
// (ceres::Jet) and core's own Dual can differentiate them.
//
//   id model           params
//   0  SIMPLE_PINHOLE  f, cx, cy
//   1  PINHOLE         fx, fy, cx, cy
//   2  SIMPLE_RADIAL   f, cx, cy, k
//   3  RADIAL          f, cx, cy, k1, k2
//   4  OPENCV          fx, fy, cx, cy, k1, k2, p1, p2
//   5  OPENCV_FISHEYE  fx, fy, cx, cy, k1, k2, k3, k4     (equidistant, OpenCV fisheye)
//   6  FULL_OPENCV     fx, fy, cx, cy, k1, k2, p1, p2, k3, k4, k5, k6  (rational)
//
// OpenCV's 5-coefficient model (k1, k2, p1, p2, k3) is FULL_OPENCV with k4=k5=k6=0.

#include <cmath>
#include <string>

namespace handlabel {

enum class CameraModelId : int {
  kSimplePinhole = 0,
  kPinhole = 1,
  kSimpleRadial = 2,
  kRadial = 3,
  kOpenCV = 4,
  kOpenCVFisheye = 5,
  kFullOpenCV = 6,
};

int NumCameraParams(CameraModelId model);
std::string CameraModelName(CameraModelId model);
// Throws InputError naming `source` when the name or id is unknown.
CameraModelId CameraModelFromName(const std::string& name, const std::string& source);
CameraModelId CameraModelFromId(int id, const std::string& source);

// Intrinsics unpacked into one layout: distortion d = (k1, k2, p1, p2, k3, k4, k5, k6)
// for the radial-tangential family; for the fisheye model d[0..3] = (k1, k2, k3, k4).
template <typename T>
struct Intrinsics {
  T fx, fy, cx, cy;
  T d[8];
  bool fisheye = false;
};

template <typename T>
Intrinsics<T> UnpackIntrinsics(CameraModelId model, const T* p) {
  Intrinsics<T> in;
  for (T& x : in.d) x = T(0.0);
  switch (model) {
    case CameraModelId::kSimplePinhole:
    case CameraModelId::kSimpleRadial:
    case CameraModelId::kRadial:
      in.fx = p[0];
      in.fy = p[0];
      in.cx = p[1];
      in.cy = p[2];
      if (model != CameraModelId::kSimplePinhole) in.d[0] = p[3];
      if (model == CameraModelId::kRadial) in.d[1] = p[4];
      break;
    case CameraModelId::kPinhole:
    case CameraModelId::kOpenCV:
    case CameraModelId::kOpenCVFisheye:
    case CameraModelId::kFullOpenCV:
      in.fx = p[0];
      in.fy = p[1];
      in.cx = p[2];
      in.cy = p[3];
      if (model == CameraModelId::kOpenCV) {
        for (int i = 0; i < 4; ++i) in.d[i] = p[4 + i];
      } else if (model == CameraModelId::kOpenCVFisheye) {
        for (int i = 0; i < 4; ++i) in.d[i] = p[4 + i];
        in.fisheye = true;
      } else if (model == CameraModelId::kFullOpenCV) {
        for (int i = 0; i < 8; ++i) in.d[i] = p[4 + i];
      }
      break;
  }
  return in;
}

// Distorts a normalised (z = 1) image point.
template <typename T>
void DistortNormalized(const Intrinsics<T>& in, const T& x, const T& y, T* xd, T* yd) {
  using std::atan;
  using std::sqrt;
  const T r2 = x * x + y * y;
  if (in.fisheye) {
    // Equidistant: theta_d = theta (1 + k1 t^2 + k2 t^4 + k3 t^6 + k4 t^8), t = atan(r).
    if (r2 < T(1e-16)) {  // sqrt is not differentiable at 0; the limit scale is 1.
      *xd = x;
      *yd = y;
      return;
    }
    const T r = sqrt(r2);
    const T theta = atan(r);
    const T t2 = theta * theta;
    const T theta_d =
        theta *
        (T(1.0) + t2 * (in.d[0] + t2 * (in.d[1] + t2 * (in.d[2] + t2 * in.d[3]))));
    const T scale = theta_d / r;
    *xd = x * scale;
    *yd = y * scale;
    return;
  }
  const T& k1 = in.d[0];
  const T& k2 = in.d[1];
  const T& p1 = in.d[2];
  const T& p2 = in.d[3];
  const T& k3 = in.d[4];
  const T& k4 = in.d[5];
  const T& k5 = in.d[6];
  const T& k6 = in.d[7];
  const T radial = (T(1.0) + r2 * (k1 + r2 * (k2 + r2 * k3))) /
                   (T(1.0) + r2 * (k4 + r2 * (k5 + r2 * k6)));
  const T xy = x * y;
  *xd = x * radial + T(2.0) * p1 * xy + p2 * (r2 + T(2.0) * x * x);
  *yd = y * radial + p1 * (r2 + T(2.0) * y * y) + T(2.0) * p2 * xy;
}

// Projects a point in camera coordinates to pixels. Returns false (and leaves uv
// untouched) for points at or behind the camera plane.
template <typename T>
bool ProjectToImage(CameraModelId model, const T* params, const T* point_in_cam, T* uv) {
  if (!(point_in_cam[2] > T(1e-12))) return false;
  const Intrinsics<T> in = UnpackIntrinsics(model, params);
  const T x = point_in_cam[0] / point_in_cam[2];
  const T y = point_in_cam[1] / point_in_cam[2];
  T xd, yd;
  DistortNormalized(in, x, y, &xd, &yd);
  uv[0] = in.fx * xd + in.cx;
  uv[1] = in.fy * yd + in.cy;
  return true;
}

}  // namespace handlabel
