#pragma once
// Motion prior of the sequence smoother (fitting/sequence_smoother.h): the acceleration
// of the 21 keypoints over three consecutive frames,
//   r = (K(x_{t-1}) - 2 K(x_t) + K(x_{t+1})) / sigma      (63 residuals)
// with K the hand's keypoints (SNAP order, world frame, metres) and sigma in metres per
// frame^2. It penalises the second difference the motion metrics measure
// (hand/metrics.h ComputeMotionMetrics), on the keypoints rather than on the
// parameters, so a pose change that moves no keypoint costs nothing and every keypoint
// counts in millimetres. A hand moving at constant velocity has zero acceleration, so
// the prior does not pull a moving hand back (no lag, unlike a velocity prior).
//
// Parameter blocks: global_orient (3), hand_pose (pose_dim), transl (3) of frame t-1,
// then of t, then of t+1; the shape (betas) is the sequence's, fixed, held by the
// functor. Analytic Jacobian from HandEvaluator::KeypointsAndJacobian; checked against
// central differences in tests/fitting/sequence_smoother_test.cc.

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <array>
#include <vector>

#include "hand/hand_evaluator.h"

namespace handlabel {

class KeypointAccelerationCost : public ceres::CostFunction {
 public:
  // `evaluator` must outlive the cost; `betas` has evaluator.num_betas() values.
  KeypointAccelerationCost(const HandEvaluator& evaluator, const Eigen::VectorXd& betas,
                           double sigma_m)
      : evaluator_(evaluator), betas_(betas), inv_sigma_(1.0 / sigma_m) {
    HL_CHECK(betas.size() == evaluator.num_betas(), "betas of the evaluator's size");
    set_num_residuals(3 * kNumHandKeypoints);
    for (int f = 0; f < 3; ++f) {
      mutable_parameter_block_sizes()->insert(mutable_parameter_block_sizes()->end(),
                                              {3, evaluator.pose_dim(), 3});
    }
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    constexpr std::array<double, 3> kCoefficients = {1.0, -2.0, 1.0};
    const int n = evaluator_.num_params();
    const int pose_dim = evaluator_.pose_dim();
    // Columns of the evaluator's Jacobian for each of a frame's blocks.
    const std::array<int, 3> column = {0, 3, 3 + pose_dim + evaluator_.num_betas()};
    const std::array<int, 3> size = {3, pose_dim, 3};
    Eigen::Map<Eigen::VectorXd> r(residuals, 3 * kNumHandKeypoints);
    r.setZero();
    std::vector<double> jacobian(jacobians ? 3 * kNumHandKeypoints * n : 0);
    for (int f = 0; f < 3; ++f) {
      const double* const* frame = parameters + 3 * f;
      double keypoints[3 * kNumHandKeypoints];
      if (jacobians == nullptr) {
        evaluator_.Keypoints(frame[0], frame[1], betas_.data(), frame[2], keypoints);
      } else {
        evaluator_.KeypointsAndJacobian(frame[0], frame[1], betas_.data(), frame[2],
                                        keypoints, jacobian.data());
      }
      const double c = kCoefficients[f] * inv_sigma_;
      r += c * Eigen::Map<const Eigen::VectorXd>(keypoints, 3 * kNumHandKeypoints);
      if (jacobians == nullptr) continue;
      for (int b = 0; b < 3; ++b) {
        double* out = jacobians[3 * f + b];
        if (out == nullptr) continue;
        for (int row = 0; row < 3 * kNumHandKeypoints; ++row) {
          for (int col = 0; col < size[b]; ++col) {
            out[row * size[b] + col] = c * jacobian[row * n + column[b] + col];
          }
        }
      }
    }
    return true;
  }

 private:
  const HandEvaluator& evaluator_;
  Eigen::VectorXd betas_;
  double inv_sigma_;
};

}  // namespace handlabel
