#pragma once
// Quadratic priors on the hand parameters.
//   PosePriorCost       distance of the 45 axis-angle joint values to a mean pose:
//                       r_i = (pose45_i - mean_i) / sigma_i. With the model's pose_mean
//                       (MANO hands_mean) and per-value sigmas this is a diagonal
//                       Gaussian; PCA coefficients are expanded by the evaluator first.
//   ShapePriorCost      r_s = betas_s / sigma (betas are unit-variance by MANO's
//                       construction, so sigma = 1 is the standard normal prior).
//   ParameterPriorCost  r = (x - target) / sigma for any block: the pull towards the
//                       previous frame (temporal smoothness, when frames are solved one
//                       after another).
//   ParameterDifferenceCost  r = (a - b) / sigma between two blocks: temporal
//                       smoothness when several frames are solved jointly.

#include <ceres/autodiff_cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "hand/hand_evaluator.h"

namespace handlabel {

template <int kPoseDim = kNumPoseParams>
class PosePriorCost {
 public:
  // `evaluator` must outlive the functor. inv_sigma: 45 values, 1 / sigma_i (radians).
  PosePriorCost(const HandEvaluator& evaluator, const Eigen::Matrix<double, 45, 1>& mean,
                const Eigen::Matrix<double, 45, 1>& inv_sigma)
      : evaluator_(evaluator), mean_(mean), inv_sigma_(inv_sigma) {
    HL_CHECK(evaluator.pose_dim() == kPoseDim, "pose size differs from the evaluator's");
  }

  template <typename T>
  bool operator()(const T* hand_pose, T* residuals) const {
    T pose45[kNumPoseParams];
    evaluator_.AxisAnglePose(hand_pose, pose45);
    for (int i = 0; i < kNumPoseParams; ++i) {
      residuals[i] = (pose45[i] - mean_[i]) * inv_sigma_[i];
    }
    return true;
  }

  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const Eigen::Matrix<double, 45, 1>& mean,
                                     const Eigen::Matrix<double, 45, 1>& inv_sigma) {
    return new ceres::AutoDiffCostFunction<PosePriorCost, kNumPoseParams, kPoseDim>(
        new PosePriorCost(evaluator, mean, inv_sigma));
  }

 private:
  const HandEvaluator& evaluator_;
  Eigen::Matrix<double, 45, 1> mean_;
  Eigen::Matrix<double, 45, 1> inv_sigma_;
};

template <int kNumBetas = 10>
class ShapePriorCost {
 public:
  explicit ShapePriorCost(double sigma) : inv_sigma_(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* betas, T* residuals) const {
    for (int s = 0; s < kNumBetas; ++s) residuals[s] = betas[s] * inv_sigma_;
    return true;
  }
  static ceres::CostFunction* Create(double sigma) {
    return new ceres::AutoDiffCostFunction<ShapePriorCost, kNumBetas, kNumBetas>(
        new ShapePriorCost(sigma));
  }

 private:
  double inv_sigma_;
};

template <int kSize>
class ParameterPriorCost {
 public:
  ParameterPriorCost(const double* target, double sigma) : inv_sigma_(1.0 / sigma) {
    for (int i = 0; i < kSize; ++i) target_[i] = target[i];
  }
  template <typename T>
  bool operator()(const T* x, T* residuals) const {
    for (int i = 0; i < kSize; ++i) residuals[i] = (x[i] - target_[i]) * inv_sigma_;
    return true;
  }
  static ceres::CostFunction* Create(const double* target, double sigma) {
    return new ceres::AutoDiffCostFunction<ParameterPriorCost, kSize, kSize>(
        new ParameterPriorCost(target, sigma));
  }

 private:
  double target_[kSize];
  double inv_sigma_;
};

template <int kSize>
class ParameterDifferenceCost {
 public:
  explicit ParameterDifferenceCost(double sigma) : inv_sigma_(1.0 / sigma) {}
  template <typename T>
  bool operator()(const T* a, const T* b, T* residuals) const {
    for (int i = 0; i < kSize; ++i) residuals[i] = (a[i] - b[i]) * inv_sigma_;
    return true;
  }
  static ceres::CostFunction* Create(double sigma) {
    return new ceres::AutoDiffCostFunction<ParameterDifferenceCost, kSize, kSize, kSize>(
        new ParameterDifferenceCost(sigma));
  }

 private:
  double inv_sigma_;
};

}  // namespace handlabel
