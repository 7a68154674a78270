#pragma once
// One view's 2D hand keypoints: the one type capture files and readers, the fitter's
// evidence, the network's answer and the label job exchange them in. Records that know
// more about a view (the capture file's visibility, the fitter's camera, a simulated
// detection's mask) hold a Keypoints2d instead of repeating its fields.

#include <Eigen/Core>

#include "hand/hand_model.h"

namespace handlabel {

// 21 pixel positions (u, v), one row per keypoint, SNAP order.
using KeypointPixels = Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor>;
// One value per keypoint, SNAP order.
using KeypointConfidences = Eigen::Matrix<double, kNumHandKeypoints, 1>;

// Positions are distorted full-image pixels, as a detector reports them, unless the
// field holding them says otherwise (the network's own answer is in crop pixels).
// Confidence is in [0, 1]; 0 = not detected, and then the position says nothing: it
// is 0 in what readers hand on and NaN in a capture file record (null in its JSON).
struct Keypoints2d {
  KeypointPixels uv_px = KeypointPixels::Zero();
  KeypointConfidences confidence = KeypointConfidences::Zero();
};

}  // namespace handlabel
