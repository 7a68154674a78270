#pragma once
// Pulls the hand towards given 3D points: the 21 keypoints and/or chosen vertices (a
// network's prediction, or triangulated keypoints), r = sqrt(w_i) (X_i - target_i) /
// sigma with per-point weights w_i >= 0 (0 = unknown point). Used to start fitting
// from the network's mesh and for the IK-style initialisation.
// Residuals: 3 per keypoint (21, SNAP order) then 3 per listed vertex.

#include <ceres/autodiff_cost_function.h>
#include <ceres/cost_function.h>

#include <cmath>
#include <vector>

#include "fitting/points3d_targets.h"
#include "hand/hand_evaluator.h"
#include "hand/hand_lbs.h"

namespace handlabel {

template <int kPoseDim = kNumPoseParams, int kNumBetas = 10>
class Points3dCost {
 public:
  // `evaluator` must outlive the functor.
  Points3dCost(const HandEvaluator& evaluator, const Points3dTargets& targets,
               double sigma)
      : evaluator_(evaluator), targets_(targets), inv_sigma_(1.0 / sigma) {
    HL_CHECK(evaluator.pose_dim() == kPoseDim && evaluator.num_betas() == kNumBetas,
             "functor sizes differ from the evaluator's");
    HL_CHECK(
        targets.keypoints.rows() == 0 || targets.keypoints.rows() == kNumHandKeypoints,
        "keypoint targets must be 21 x 3");
    HL_CHECK(
        targets.vertices.rows() == static_cast<Eigen::Index>(targets.vertex_ids.size()),
        "one target per vertex id");
    if (targets_.keypoints.rows() > 0 && targets_.keypoint_weights.size() == 0) {
      targets_.keypoint_weights = Eigen::VectorXd::Ones(kNumHandKeypoints);
    }
  }
  int num_residuals() const {
    return 3 * static_cast<int>(targets_.keypoints.rows() + targets_.vertices.rows());
  }

  template <typename T>
  bool operator()(const T* orient, const T* pose, const T* betas, const T* transl,
                  T* residuals) const {
    HandPoseState<T> state;
    evaluator_.Pose(orient, pose, betas, transl, &state);
    int row = 0;
    if (targets_.keypoints.rows() > 0) {
      T keypoints[3 * kNumHandKeypoints];
      evaluator_.KeypointsFromState(state, keypoints);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        const double s =
            std::sqrt(std::max(0.0, targets_.keypoint_weights[k])) * inv_sigma_;
        for (int c = 0; c < 3; ++c) {
          residuals[row++] = (keypoints[3 * k + c] - targets_.keypoints(k, c)) * s;
        }
      }
    }
    if (!targets_.vertex_ids.empty()) {
      std::vector<T> vertices(3 * targets_.vertex_ids.size());
      evaluator_.VerticesFromState(state, targets_.vertex_ids, vertices.data());
      for (size_t i = 0; i < targets_.vertex_ids.size(); ++i) {
        for (int c = 0; c < 3; ++c) {
          residuals[row++] = (vertices[3 * i + c] - targets_.vertices(i, c)) * inv_sigma_;
        }
      }
    }
    return true;
  }

  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const Points3dTargets& targets, double sigma) {
    auto* functor = new Points3dCost(evaluator, targets, sigma);
    return new ceres::AutoDiffCostFunction<Points3dCost, ceres::DYNAMIC, 3, kPoseDim,
                                           kNumBetas, 3>(functor,
                                                         functor->num_residuals());
  }

 private:
  const HandEvaluator& evaluator_;
  Points3dTargets targets_;
  double inv_sigma_;
};

// The keypoint part of Points3dCost (no vertices) with the analytic Jacobian of
// HandEvaluator::KeypointsAndJacobian: the IK-style initialisation's cost, several times
// cheaper than Jets. Parameter blocks (3, pose_dim, num_betas, 3); 63 residuals.
class Keypoints3dCostFunction : public ceres::CostFunction {
 public:
  // `evaluator` must outlive the cost function; weights: 21 values >= 0.
  Keypoints3dCostFunction(const HandEvaluator& evaluator, const Points3d& keypoints,
                          const Eigen::VectorXd& weights, double sigma)
      : evaluator_(evaluator), targets_(keypoints) {
    HL_CHECK(keypoints.rows() == kNumHandKeypoints && weights.size() == kNumHandKeypoints,
             "21 keypoints and weights");
    scale_ = weights.cwiseMax(0.0).cwiseSqrt() / sigma;
    set_num_residuals(3 * kNumHandKeypoints);
    mutable_parameter_block_sizes()->assign(
        {3, evaluator.pose_dim(), evaluator.num_betas(), 3});
  }
  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const Points3d& keypoints,
                                     const Eigen::VectorXd& weights, double sigma) {
    return new Keypoints3dCostFunction(evaluator, keypoints, weights, sigma);
  }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const int n = evaluator_.num_params();
    double keypoints[3 * kNumHandKeypoints];
    std::vector<double> jac;
    if (jacobians != nullptr) {
      jac.resize(3 * kNumHandKeypoints * n);
      evaluator_.KeypointsAndJacobian(parameters[0], parameters[1], parameters[2],
                                      parameters[3], keypoints, jac.data());
    } else {
      evaluator_.Keypoints(parameters[0], parameters[1], parameters[2], parameters[3],
                           keypoints);
    }
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      for (int c = 0; c < 3; ++c) {
        residuals[3 * k + c] = (keypoints[3 * k + c] - targets_(k, c)) * scale_[k];
      }
    }
    if (jacobians == nullptr) return true;
    const int sizes[4] = {3, evaluator_.pose_dim(), evaluator_.num_betas(), 3};
    int offset = 0;
    for (int b = 0; b < 4; ++b) {
      if (jacobians[b] != nullptr) {
        for (int r = 0; r < 3 * kNumHandKeypoints; ++r) {
          for (int c = 0; c < sizes[b]; ++c) {
            jacobians[b][r * sizes[b] + c] = jac[r * n + offset + c] * scale_[r / 3];
          }
        }
      }
      offset += sizes[b];
    }
    return true;
  }

 private:
  const HandEvaluator& evaluator_;
  Points3d targets_;
  Eigen::VectorXd scale_;
};

}  // namespace handlabel
