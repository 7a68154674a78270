#include "capture/detector_keypoint_samples.h"

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void DetectorKeypointSampleOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "min_views", min_views, 2);
  RequireGreater(source, "inlier_threshold_px", inlier_threshold_px, 0.0);
}

std::vector<DetectorKeypointSample> DetectorKeypointSamples(
    const FrameSource& source, const std::vector<std::string>& ids,
    const DetectorKeypointSampleOptions& options) {
  options.Check("DetectorKeypointSampleOptions");
  RobustTriangulationOptions triangulation;
  triangulation.inlier_threshold_px = options.inlier_threshold_px;
  triangulation.min_inliers = options.min_views;
  std::vector<DetectorKeypointSample> samples;
  for (const std::string& id : ids) {
    FrameInput frame;
    try {
      frame = source.Load(id);
    } catch (const InputError&) {
      continue;  // e.g. a frame where the detector found no hand in any view
    }
    if (!frame.ground_truth || !frame.ground_truth->params ||
        frame.keypoints_2d.empty()) {
      continue;
    }
    DetectorKeypointSample sample;
    sample.truth = *frame.ground_truth->params;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      std::vector<ViewObservation> observations;
      for (size_t v = 0; v < frame.keypoints_2d.size(); ++v) {
        const std::optional<Keypoints2d>& view = frame.keypoints_2d[v];
        if (!view || view->confidence[k] <= 0) continue;
        observations.push_back(
            {static_cast<int>(v), view->uv_px.row(k).transpose(), view->confidence[k]});
      }
      const RobustTriangulation point =
          TriangulateRobust(frame.rig, observations, triangulation);
      sample.found[k] = point.valid;
      if (point.valid) sample.detected.row(k) = point.point.transpose();
    }
    samples.push_back(sample);
  }
  if (samples.empty()) {
    throw InputError(source.Describe(), "frames",
                     "frames with ground truth hand parameters and 2D keypoints", "none");
  }
  return samples;
}

}  // namespace handlabel
