#pragma once
// Quality checks on the network's answer for one frame: is it finite and of plausible
// size, do enough views see the hand confidently, does the predicted 3D hand reproject
// onto the network's own 2D keypoints in every view, and do the views agree with each
// other (2D keypoints triangulated across views vs the 3D keypoints). The fallback
// policy (refine.mode fallback) fits from 2D evidence alone when any check fails.
// Thresholds come from the job's `refine` section (QualityThresholds).

#include <string>
#include <vector>

#include "pipeline/job_config.h"
#include "pipeline/label_stages.h"

namespace handlabel {

struct QualityFlag {
  std::string name;  // finite | range | enough_views | reprojection | view_agreement
  bool passed = false;
  double value = 0;      // the measured quantity (units in `detail`)
  double threshold = 0;  // what it was compared with
  std::string detail;    // human-readable explanation
};

struct QualityReport {
  std::vector<QualityFlag> flags;  // always all five, in the order above
  bool Passed() const;
  // Names of the failed checks, comma separated ("" when all passed).
  std::string FailedNames() const;
};

// The checks, against the rig of the frame. Each view's 2D keypoints count only where
// their confidence is >= thresholds.min_confidence; a view counts as seeing the hand
// when its mean keypoint confidence is >= min_confidence.
//   finite          every coordinate and confidence is finite (value: bad entries)
//   range           hand span within [min_hand_span_m, max_hand_span_m] and every
//                   keypoint in front of every confident view (value: span in m)
//   enough_views    confident views >= min_views (value: count)
//   reprojection    worst per-view RMS pixel distance between projected 3D keypoints
//                   and 2D keypoints <= max_reprojection_px (value: px)
//   view_agreement  mean distance between keypoints triangulated from the confident
//                   views and the 3D keypoints <= max_view_disagreement_mm (value: mm)
QualityReport CheckPrediction(const Rig& rig, const MeshPrediction& prediction,
                              const QualityThresholds& thresholds);

}  // namespace handlabel
