#pragma once
// 2D keypoint evidence of one camera view for the fitter: the camera and its 21
// detected keypoints (hand/keypoints2d.h).

#include "geometry/rig.h"
#include "hand/keypoints2d.h"

namespace handlabel {

struct KeypointView {
  RigCamera camera;  // intrinsics (with distortion) and cam_from_world
  // Distorted pixels, as detected. Confidence >= 0 each (0 = not detected, ignored);
  // it multiplies the squared error.
  Keypoints2d keypoints;
};

}  // namespace handlabel
