#pragma once
// Helpers for code templated on the scalar: double, core's Dual<N> and ceres::Jet
// (both first-order duals with public members `a` (value) and `v` (derivatives)).

namespace handlabel {

// Value part.
inline double ScalarPart(double x) { return x; }
template <typename T>
double ScalarPart(const T& x) {
  return x.a;
}

// *acc += c * x without the temporary dual that `*acc += c * x` creates; the
// multiply-add of dense blend shapes dominates the dual forward pass.
inline void AddScaled(double c, double x, double* acc) { *acc += c * x; }
template <typename T>
void AddScaled(double c, const T& x, T* acc) {
  acc->a += c * x.a;
  acc->v += c * x.v;
}

// *acc += x * y (product rule) without temporaries.
inline void AddProduct(double x, double y, double* acc) { *acc += x * y; }
template <typename T>
void AddProduct(const T& x, const T& y, T* acc) {
  acc->v += x.a * y.v + y.a * x.v;
  acc->a += x.a * y.a;
}

// Dot product of two 3-vectors plus `init`.
template <typename T>
T Dot3(const T* x, int x_stride, const T* y, int y_stride, const T& init) {
  T acc = init;
  AddProduct(x[0], y[0], &acc);
  AddProduct(x[x_stride], y[y_stride], &acc);
  AddProduct(x[2 * x_stride], y[2 * y_stride], &acc);
  return acc;
}

}  // namespace handlabel
