#include "geometry/rigid3.h"

#include <Eigen/SVD>
#include <cmath>

namespace handlabel {

Points3d TransformPoints(const Rigid3& target_from_source, const Points3d& points) {
  Points3d out(points.rows(), 3);
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    out.row(i) =
        (target_from_source * Eigen::Vector3d(points.row(i).transpose())).transpose();
  }
  return out;
}

Matrix3x4d Rigid3::ToMatrix() const {
  Matrix3x4d m;
  m.leftCols<3>() = rotation.toRotationMatrix();
  m.col(3) = translation;
  return m;
}

Rigid3 Rigid3::FromMatrix(const Matrix3x4d& matrix) {
  const Eigen::Matrix3d r = matrix.leftCols<3>();
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(r, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d nearest = svd.matrixU() * svd.matrixV().transpose();
  if (nearest.determinant() < 0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1;
    nearest = u * svd.matrixV().transpose();
  }
  return Rigid3(Eigen::Quaterniond(nearest), matrix.col(3));
}

Rigid3 LookAt(const Eigen::Vector3d& eye, const Eigen::Vector3d& target,
              const Eigen::Vector3d& up) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(up);
  if (x.norm() < 1e-9) x = z.unitOrthogonal();  // looking along `up`
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);  // points "down" in the image
  Eigen::Matrix3d world_from_cam;
  world_from_cam << x, y, z;
  const Eigen::Matrix3d r = world_from_cam.transpose();
  return Rigid3(Eigen::Quaterniond(r), -(r * eye));
}

double RotationAngleBetween(const Rigid3& a, const Rigid3& b) {
  return a.rotation.angularDistance(b.rotation);
}

}  // namespace handlabel
