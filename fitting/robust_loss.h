#pragma once
// Robust losses applied inside a cost functor, per observation. Ceres applies a
// LossFunction to a whole residual block; our keypoint block holds every keypoint of
// every view (so the forward pass runs once), so each 2D error e is robustified on its
// own: r = f(s) e with s = |e|^2 and f(s) = sqrt(rho(s) / s), whence |r|^2 = rho(s).
// Gauss-Newton on r matches Ceres' own robustification to first order.
//   Huber   rho(s) = s (s <= a^2), 2 a sqrt(s) - a^2 otherwise
//   Cauchy  rho(s) = a^2 log(1 + s / a^2)
// `scale` a is in the units of e (pixels after confidence weighting).

#include <cmath>
#include <string>

namespace handlabel {

enum class RobustLossType { kTrivial, kHuber, kCauchy };
// "trivial" | "huber" | "cauchy"; throws InputError naming `source` otherwise.
RobustLossType RobustLossFromName(const std::string& name, const std::string& source);
std::string RobustLossName(RobustLossType type);

struct RobustLoss {
  RobustLossType type = RobustLossType::kHuber;
  double scale = 1.0;  // a > 0
};

// Below this s, f = 1 and f' = 0 (both losses are quadratic there to first order).
constexpr double kRobustTinySquaredNorm = 1e-20;

// f(s) for any scalar type (double, ceres::Jet).
template <typename T>
T RobustFactor(const RobustLoss& loss, const T& s) {
  using std::log;
  using std::sqrt;
  const double a2 = loss.scale * loss.scale;
  if (loss.type == RobustLossType::kTrivial || s < T(kRobustTinySquaredNorm))
    return T(1.0);
  if (loss.type == RobustLossType::kHuber) {
    if (s <= T(a2)) return T(1.0);
    return sqrt((T(2.0 * loss.scale) * sqrt(s) - T(a2)) / s);
  }
  return sqrt(T(a2) * log(T(1.0) + s / T(a2)) / s);
}

// f(s) and df/ds in doubles, for analytic Jacobians: dr/de = f I + 2 f' e e^T.
inline void RobustFactorAndDerivative(const RobustLoss& loss, double s, double* f,
                                      double* df) {
  const double a = loss.scale, a2 = a * a;
  *f = 1.0;
  *df = 0.0;
  if (loss.type == RobustLossType::kTrivial || s < kRobustTinySquaredNorm) return;
  double rho, drho;
  if (loss.type == RobustLossType::kHuber) {
    if (s <= a2) return;
    const double r = std::sqrt(s);
    rho = 2.0 * a * r - a2;
    drho = a / r;
  } else {
    rho = a2 * std::log1p(s / a2);
    drho = 1.0 / (1.0 + s / a2);
  }
  *f = std::sqrt(rho / s);
  *df = (drho * s - rho) / (s * s) / (2.0 * *f);
}

}  // namespace handlabel
