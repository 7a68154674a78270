#pragma once
// 2D keypoint evidence of one camera view: the camera and 21 detected keypoints (SNAP
// order) with confidences.

#include <Eigen/Core>

#include "core/hand_model.h"
#include "core/rig.h"

namespace handlabel {

using KeypointPixels = Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor>;
using KeypointConfidences = Eigen::Matrix<double, kNumHandKeypoints, 1>;

struct KeypointView {
  RigCamera camera;  // intrinsics (with distortion) and cam_from_world
  KeypointPixels uv_px = KeypointPixels::Zero();  // distorted pixels, as detected
  // >= 0 each; 0 = not detected (ignored). Multiplies the squared error.
  KeypointConfidences confidence = KeypointConfidences::Zero();
};

}  // namespace handlabel
