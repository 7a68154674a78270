#pragma once
// 3D targets for the hand: the 21 keypoints and/or chosen vertices (a network's
// prediction, or triangulated keypoints). A plain struct apart from its cost functor
// (fitting/points3d_cost.h) so that callers of the fitter do not include Ceres.

#include <Eigen/Core>
#include <vector>

#include "hand/hand_lbs.h"

namespace handlabel {

struct Points3dTargets {
  Points3d keypoints;                // 21 x 3 or empty
  Eigen::VectorXd keypoint_weights;  // 21 or empty (= all 1)
  std::vector<int> vertex_ids;       // vertices to pull (may be empty)
  Points3d vertices;                 // vertex_ids.size() x 3
};

}  // namespace handlabel
