#pragma once
// Rigid transform target_from_source: p_target = rotation * p_source + translation.
//
// Storage: `rotation` is an Eigen unit quaternion whose coeffs() are laid out
// (x, y, z, w), the order ceres::EigenQuaternionManifold expects, so
// `rotation.coeffs().data()` (4 doubles) and `translation.data()` (3 doubles) can be
// handed to Ceres as two parameter blocks and optimised in place.
// File formats that use (w, x, y, z) (COLMAP, our JSON) convert at the reader.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "core/point_arrays.h"

namespace handlabel {

using Matrix3x4d = Eigen::Matrix<double, 3, 4>;

struct Rigid3 {
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();

  Rigid3() = default;
  Rigid3(const Eigen::Quaterniond& r, const Eigen::Vector3d& t)
      : rotation(r.normalized()), translation(t) {}

  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return rotation * p + translation;
  }
  // (a_from_b * b_from_c) = a_from_c.
  Rigid3 operator*(const Rigid3& other) const {
    return Rigid3(rotation * other.rotation, rotation * other.translation + translation);
  }
  Rigid3 Inverse() const {
    const Eigen::Quaterniond inv = rotation.conjugate();
    return Rigid3(inv, -(inv * translation));
  }
  // [R | t] as a 3x4 matrix.
  Matrix3x4d ToMatrix() const;
  // From [R | t]; R is re-orthonormalised (nearest rotation) so that slightly
  // non-orthogonal matrices from text files are accepted.
  static Rigid3 FromMatrix(const Matrix3x4d& matrix);
  // For cam_from_world: the camera centre in world coordinates (-R^T t).
  Eigen::Vector3d SourceOrigin() const { return -(rotation.conjugate() * translation); }
};

// Every row of `points` (in the source frame) in the target frame, as
// target_from_source * p: e.g. keypoints from a camera to the world with the camera's
// cam_from_world.Inverse().
Points3d TransformPoints(const Rigid3& target_from_source, const Points3d& points);

// cam_from_world of an OpenCV camera (z forward, y down) at `eye` looking at `target`;
// `up` is the world direction that should appear upwards in the image.
Rigid3 LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
              const Eigen::Vector3d& up);

// Angle of the relative rotation between two transforms, in radians.
double RotationAngleBetween(const Rigid3& a, const Rigid3& b);

}  // namespace handlabel
