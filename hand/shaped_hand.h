#pragma once
// The shaped hand before posing, the first step of the forward pass (hand_lbs.h):
//   vertices = v_template + shapedirs * betas,  joints = joint_regressor * vertices
// PoseHand poses it; exports (a glTF skeleton's bind pose) need it alone.

#include <Eigen/Core>

#include "core/point_arrays.h"
#include "hand/hand_model.h"

namespace handlabel {

struct ShapedHand {
  Points3d vertices;  // V x 3
  Points3d joints;    // 16 x 3, native order (the rest joints)
};

// betas: at most the model's count (missing ones are 0); more throws InputError.
ShapedHand ShapeHand(const HandModel& model, const Eigen::VectorXd& betas);

}  // namespace handlabel
