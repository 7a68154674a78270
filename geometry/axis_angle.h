#pragma once
// Axis-angle to rotation matrix, templated on the scalar (double, Dual<N>, ceres::Jet).

#include <cmath>

namespace handlabel {

// Rotation matrix (row-major 3x3) from axis-angle w: R = I + a [w]x + b [w]x^2 with
// a = sin(t)/t, b = (1 - cos(t))/t^2, t = |w|. Below t^2 = 1e-8 a and b come from their
// Taylor series in t^2 (no sqrt), so values and derivatives stay exact at w = 0 for
// Jets and Duals (error < 1e-18).
template <typename T>
void AxisAngleToRotation(const T* w, T* r) {
  using std::cos;
  using std::sin;
  using std::sqrt;
  const T theta2 = w[0] * w[0] + w[1] * w[1] + w[2] * w[2];
  T a, b;
  if (theta2 > T(1e-8)) {
    const T theta = sqrt(theta2);
    a = sin(theta) / theta;
    b = (T(1.0) - cos(theta)) / theta2;
  } else {
    a = T(1.0) - theta2 / 6.0;
    b = T(0.5) - theta2 / 24.0;
  }
  // [w]x^2 = w w^T - t^2 I.
  r[0] = T(1.0) + b * (w[0] * w[0] - theta2);
  r[1] = b * (w[0] * w[1]) - a * w[2];
  r[2] = b * (w[0] * w[2]) + a * w[1];
  r[3] = b * (w[0] * w[1]) + a * w[2];
  r[4] = T(1.0) + b * (w[1] * w[1] - theta2);
  r[5] = b * (w[1] * w[2]) - a * w[0];
  r[6] = b * (w[0] * w[2]) - a * w[1];
  r[7] = b * (w[1] * w[2]) + a * w[0];
  r[8] = T(1.0) + b * (w[2] * w[2] - theta2);
}

}  // namespace handlabel
