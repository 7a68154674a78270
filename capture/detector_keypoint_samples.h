#pragma once
// Training samples for the model of where a 2D detector puts its keypoints
// (hand/detector_keypoints.h) from a capture that has both the detector's 2D keypoints
// and exact ground truth: a synthetic capture rendered with the realistic look and run
// through `handlabel detect` (docs/fitting.md "Where the detector's keypoints are").
// Per frame, each keypoint is triangulated robustly from the views that found it and
// paired with the truth's hand parameters.

#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "geometry/triangulation.h"
#include "hand/detector_keypoints.h"

namespace handlabel {

struct DetectorKeypointSampleOptions {
  // Views that must agree on a keypoint (inliers of the robust triangulation, >= 2):
  // more views, fewer wrong points.
  int min_views = 3;
  // A view agrees when its keypoint reprojects within this many pixels (> 0).
  double inlier_threshold_px = 8.0;
  // Throws InputError naming `source` and the field.
  void Check(const std::string& source) const;
};

// One sample per frame of `ids` that has ground truth with hand parameters and 2D
// keypoints; keypoints not triangulated are marked not found. Frames without them, or
// whose files the source refuses (a frame where the detector found nothing), are
// skipped. Throws InputError when no frame has both.
std::vector<DetectorKeypointSample> DetectorKeypointSamples(
    const FrameSource& source, const std::vector<std::string>& ids,
    const DetectorKeypointSampleOptions& options);

}  // namespace handlabel
