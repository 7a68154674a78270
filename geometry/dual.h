#pragma once
// Forward-mode dual numbers: a value plus N partial derivatives. The camera and hand
// model code is templated on the scalar so that one implementation serves plain
// doubles, these duals (Jacobians inside core, which does not link Ceres) and
// ceres::Jet in the fitting layer.

#include <Eigen/Core>
#include <cmath>

namespace handlabel {

template <int N>
struct Dual {
  double a = 0;                                                         // value
  Eigen::Matrix<double, N, 1> v = Eigen::Matrix<double, N, 1>::Zero();  // derivatives

  Dual() = default;
  Dual(double value) : a(value) {}  // NOLINT: constants promote implicitly.
  Dual(double value, int k) : a(value) { v[k] = 1.0; }

  Dual& operator+=(const Dual& o) {
    a += o.a;
    v += o.v;
    return *this;
  }
  Dual& operator-=(const Dual& o) {
    a -= o.a;
    v -= o.v;
    return *this;
  }
  Dual& operator*=(const Dual& o) {
    v = v * o.a + o.v * a;
    a *= o.a;
    return *this;
  }
  Dual& operator/=(const Dual& o) {
    v = (v - o.v * (a / o.a)) / o.a;
    a /= o.a;
    return *this;
  }
};

template <int N>
Dual<N> operator+(Dual<N> x, const Dual<N>& y) {
  return x += y;
}
template <int N>
Dual<N> operator-(Dual<N> x, const Dual<N>& y) {
  return x -= y;
}
template <int N>
Dual<N> operator*(Dual<N> x, const Dual<N>& y) {
  return x *= y;
}
template <int N>
Dual<N> operator/(Dual<N> x, const Dual<N>& y) {
  return x /= y;
}
template <int N>
Dual<N> operator+(Dual<N> x, double y) {
  x.a += y;
  return x;
}
template <int N>
Dual<N> operator+(double y, Dual<N> x) {
  x.a += y;
  return x;
}
template <int N>
Dual<N> operator-(Dual<N> x, double y) {
  x.a -= y;
  return x;
}
template <int N>
Dual<N> operator-(double y, const Dual<N>& x) {
  Dual<N> r;
  r.a = y - x.a;
  r.v = -x.v;
  return r;
}
template <int N>
Dual<N> operator-(const Dual<N>& x) {
  Dual<N> r;
  r.a = -x.a;
  r.v = -x.v;
  return r;
}
template <int N>
Dual<N> operator*(Dual<N> x, double y) {
  x.a *= y;
  x.v *= y;
  return x;
}
template <int N>
Dual<N> operator*(double y, Dual<N> x) {
  x.a *= y;
  x.v *= y;
  return x;
}
template <int N>
Dual<N> operator/(Dual<N> x, double y) {
  x.a /= y;
  x.v /= y;
  return x;
}
template <int N>
Dual<N> operator/(double y, const Dual<N>& x) {
  return Dual<N>(y) / x;
}
template <int N>
bool operator<(const Dual<N>& x, const Dual<N>& y) {
  return x.a < y.a;
}
template <int N>
bool operator>(const Dual<N>& x, const Dual<N>& y) {
  return x.a > y.a;
}
template <int N>
bool operator<(const Dual<N>& x, double y) {
  return x.a < y;
}
template <int N>
bool operator>(const Dual<N>& x, double y) {
  return x.a > y;
}

template <int N>
Dual<N> sqrt(const Dual<N>& x) {
  Dual<N> r;
  r.a = std::sqrt(x.a);
  r.v = x.v / (2.0 * r.a);
  return r;
}
template <int N>
Dual<N> atan(const Dual<N>& x) {
  Dual<N> r;
  r.a = std::atan(x.a);
  r.v = x.v / (1.0 + x.a * x.a);
  return r;
}
template <int N>
Dual<N> atan2(const Dual<N>& y, const Dual<N>& x) {
  Dual<N> r;
  r.a = std::atan2(y.a, x.a);
  r.v = (y.v * x.a - x.v * y.a) / (x.a * x.a + y.a * y.a);
  return r;
}
template <int N>
Dual<N> sin(const Dual<N>& x) {
  Dual<N> r;
  r.a = std::sin(x.a);
  r.v = x.v * std::cos(x.a);
  return r;
}
template <int N>
Dual<N> cos(const Dual<N>& x) {
  Dual<N> r;
  r.a = std::cos(x.a);
  r.v = -x.v * std::sin(x.a);
  return r;
}

}  // namespace handlabel
