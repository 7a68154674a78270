#pragma once
// Anatomical joint limits as hinge residuals (hand/hand_anatomy.h): for each of the 15
// non-root joints and each of (twist, spread, bend),
//   r = sqrt(weight) * (max(0, angle - max) + max(0, min - angle))      [radians]
// zero inside the limits, linear outside (so the squared cost grows quadratically).
// Parameter block: hand_pose (kPoseDim; PCA coefficients are expanded by the
// evaluator first). 45 residuals, index 3 * (joint - 1) + axis.

#include <ceres/autodiff_cost_function.h>

#include <cmath>

#include "hand/hand_anatomy.h"
#include "hand/hand_evaluator.h"

namespace handlabel {

template <int kPoseDim = kNumPoseParams>
class JointLimitCost {
 public:
  // `evaluator` must outlive the functor.
  JointLimitCost(const HandEvaluator& evaluator, const HandAnatomy& anatomy,
                 const HandLimits& limits, double weight)
      : evaluator_(evaluator),
        anatomy_(anatomy),
        limits_(limits),
        scale_(std::sqrt(weight)) {
    HL_CHECK(evaluator.pose_dim() == kPoseDim, "pose size differs from the evaluator's");
  }

  template <typename T>
  bool operator()(const T* hand_pose, T* residuals) const {
    T pose45[kNumPoseParams], angles[kNumPoseParams];
    evaluator_.AxisAnglePose(hand_pose, pose45);
    HandAnatomicalAngles(anatomy_, pose45, angles);
    LimitResiduals(limits_, angles, residuals);
    for (int i = 0; i < kNumPoseParams; ++i) residuals[i] = residuals[i] * scale_;
    return true;
  }

  static ceres::CostFunction* Create(const HandEvaluator& evaluator,
                                     const HandAnatomy& anatomy, const HandLimits& limits,
                                     double weight) {
    return new ceres::AutoDiffCostFunction<JointLimitCost, kNumPoseParams, kPoseDim>(
        new JointLimitCost(evaluator, anatomy, limits, weight));
  }

 private:
  const HandEvaluator& evaluator_;
  HandAnatomy anatomy_;
  HandLimits limits_;
  double scale_;
};

}  // namespace handlabel
