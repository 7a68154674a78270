#pragma once
// Forward pass of a MANO-compatible hand: parameters -> vertices, 16 joints and 21
// keypoints (SNAP order). Semantics follow MANO exactly:
//   v_shaped = v_template + shapedirs * betas
//   J        = joint_regressor * v_shaped                 (rest joints, 16 x 3)
//   v_posed  = v_shaped + posedirs * vec(R_j - I, j = 1..15)
//   G_j      = chain of [R_j | J_j - J_parent] from the root; the root rotates about J_0
//   v        = sum_j w_vj * G_j * (v_posed - J_j)  + transl
//   joints   = G_j translations + transl; keypoints = joints + tip vertices, reordered
// Rotations are axis-angle (Rodrigues); hand_pose holds the 15 non-root joints in
// native order (3 values each).

#include <Eigen/Core>
#include <vector>

#include "core/point_arrays.h"
#include "hand/hand_model.h"

namespace handlabel {

// MANO-compatible parameters, as written into labels.
struct HandParams {
  Eigen::Vector3d global_orient = Eigen::Vector3d::Zero();  // root axis-angle
  Eigen::Matrix<double, kNumPoseParams, 1> hand_pose =
      Eigen::Matrix<double, kNumPoseParams, 1>::Zero();  // 15 joints, axis-angle
  Eigen::VectorXd betas;                                 // <= model's count; missing = 0
  Eigen::Vector3d transl = Eigen::Vector3d::Zero();
};

struct HandMesh {
  Points3d vertices;   // V x 3
  Points3d joints;     // 16 x 3, native order
  Points3d keypoints;  // 21 x 3, SNAP order
};

// Evaluates the full mesh in doubles.
HandMesh PoseHand(const HandModel& model, const HandParams& params);

// Axis-angle hand_pose from PCA coefficients (any count up to the basis size):
// pose = coeffs * basis[:n] (+ pose_mean unless flat_hand_mean).
Eigen::Matrix<double, kNumPoseParams, 1> HandPoseFromPca(const HandModel& model,
                                                         const Eigen::VectorXd& coeffs,
                                                         bool flat_hand_mean);

}  // namespace handlabel
