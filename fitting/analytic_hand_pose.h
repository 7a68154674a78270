#pragma once
// A closed-form start for the hand pose from 3D keypoints, for the IK-style
// initialisation: walking down the kinematic tree from the wrist, each joint turns its
// bone (towards its child joint, or its fingertip) by the smallest rotation that lays it
// along the target bone. It ignores twist about the bone and the shape, so it is a
// start for the least-squares solve, which then needs a fraction of its iterations.

#include <Eigen/Core>

#include "hand/hand_lbs.h"
#include "hand/hand_model.h"

namespace handlabel {

// `rest_keypoints` and `target_keypoints`: 21 x 3, SNAP order (hand/hand_model.h); the
// rest hand unposed at the origin, the targets in the frame where the wrist has the
// rotation `root_rotation`. Keypoints with weight <= 0 are unknown: a joint whose bone
// ends are not both known keeps a zero rotation. Writes the 45 axis-angle values of
// joints 1-15 (native order) to `pose45`.
void AnalyticHandPose(const Points3d& rest_keypoints, const Points3d& target_keypoints,
                      const Eigen::VectorXd& weights,
                      const Eigen::Matrix3d& root_rotation, double* pose45);

}  // namespace handlabel
