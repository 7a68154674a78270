#pragma once
// Quality checks on the network's answer for one frame: is it finite and of plausible
// size, do enough views see the hand confidently, does the predicted 3D hand reproject
// onto the network's own 2D keypoints in every view, and do the views agree with each
// other (2D keypoints triangulated across views vs the 3D keypoints). The fallback
// policy (refine.mode fallback) fits from 2D evidence alone when any check fails.
// Thresholds come from the job's `refine` section (QualityThresholds).

#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fitting/ceres_hand_fitter.h"
#include "pipeline/job_config.h"
#include "pipeline/label_stages.h"

namespace handlabel {

struct QualityFlag {
  // finite | range | enough_views | reprojection | view_agreement | detector_agreement
  std::string name;
  bool passed = false;
  double value = 0;      // the measured quantity (units in `detail`)
  double threshold = 0;  // what it was compared with
  std::string detail;    // human-readable explanation
};

// {name, passed, value, threshold, detail}: how labels record a check.
nlohmann::json QualityFlagJson(const QualityFlag& flag);

struct QualityReport {
  std::vector<QualityFlag> flags;  // in the order its check function lists them
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
// With `file_2d` (the frame's 2D keypoints from files, one entry per view, e.g. a
// detector's; not null and not empty), one more, judged against evidence the network
// did not make:
//   detector_agreement  median over the views with confident file 2D of the RMS pixel
//                   distance between projected 3D keypoints and the file's confident
//                   keypoints <= max_detector_rms_px (value: px); fails when no view
//                   has confident file 2D
QualityReport CheckPrediction(
    const Rig& rig, const MeshPrediction& prediction, const QualityThresholds& thresholds,
    const std::vector<std::optional<Keypoints2d>>* file_2d = nullptr);

// Silhouette conflict: does a fit with silhouettes still agree with the 2D keypoints,
// and does its hand cover the observed hand mask? Masks show the visible hand only, and
// an object nobody masked, a wrong mask or a bad match can pull the fit away from the
// keypoints; the keypoints-only fit it started from (HandFitResult::keypoints_only) is
// the reference. The fitter's label then prefers the keypoints-only fit
// (pipeline/ceres_label_fitter.h).
struct SilhouetteCheckThresholds {
  // Largest rise (px) of the keypoint reprojection RMS, averaged over the views with
  // keypoints, from the keypoints-only fit to the silhouette fit. Chosen on 48 object
  // frames (3 tuning seeds, docs/fitting.md "Occlusion"): 0.2 px beat 0.1, 0.15, 0.3
  // and 0.5 (MPJPE 2.29 mm vs 2.37, 2.33, 2.33, 2.40).
  double max_keypoint_rms_rise_px = 0.2;
  // Smallest per-view silhouette IoU of the silhouette fit (occluded pixels left out,
  // views with a mask only): a sanity bound for gross failures (0.53 was the lowest
  // of an accepted fit in those frames).
  double min_view_iou = 0.5;
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

// Flags, in this order:
//   keypoint_agreement  mean over views of (RMS of the silhouette fit - RMS of the
//                       keypoints-only fit) <= max_keypoint_rms_rise_px (value: px)
//   silhouette_iou      worst view's IoU of the silhouette fit >= min_view_iou (value)
QualityReport CheckSilhouetteFit(const HandFitStageResult& silhouette_fit,
                                 const HandFitStageResult& keypoints_only,
                                 const SilhouetteCheckThresholds& thresholds);

}  // namespace handlabel
