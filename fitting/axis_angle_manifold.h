#pragma once
// The root rotation of a hand stays a MANO axis-angle vector (what labels store and
// HandEvaluator reads) but is optimised on SO(3): x (+) delta = log(exp(delta) exp(x)),
// a left perturbation, so steps behave the same at every rotation and never cross the
// angle = pi singularity of the plain vector. Derivatives by ceres::AutoDiffManifold.

#include <ceres/autodiff_manifold.h>
#include <ceres/rotation.h>

namespace handlabel {

struct AxisAngleManifoldFunctor {
  template <typename T>
  bool Plus(const T* x, const T* delta, T* x_plus_delta) const {
    T qx[4], qd[4], q[4];
    ceres::AngleAxisToQuaternion(x, qx);
    ceres::AngleAxisToQuaternion(delta, qd);
    ceres::QuaternionProduct(qd, qx, q);
    ceres::QuaternionToAngleAxis(q, x_plus_delta);
    return true;
  }
  template <typename T>
  bool Minus(const T* y, const T* x, T* y_minus_x) const {
    // log(exp(y) exp(x)^-1).
    T qy[4], qx[4], q[4];
    ceres::AngleAxisToQuaternion(y, qy);
    ceres::AngleAxisToQuaternion(x, qx);
    qx[1] = -qx[1];
    qx[2] = -qx[2];
    qx[3] = -qx[3];
    ceres::QuaternionProduct(qy, qx, q);
    ceres::QuaternionToAngleAxis(q, y_minus_x);
    return true;
  }
};

inline ceres::Manifold* CreateAxisAngleManifold() {
  return new ceres::AutoDiffManifold<AxisAngleManifoldFunctor, 3, 3>();
}

}  // namespace handlabel
