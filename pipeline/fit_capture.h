#pragma once
// `handlabel fit`: fits the hand model (fitting/ceres_hand_fitter.h) to every chosen
// frame of a capture in the native layout (capture/capture_reader.h), from its 2D
// keypoints (simulated detections or ground-truth projections) and masks, and writes
//   <out>/frames/<frame>.json   parameters (MANO-compatible), 21 keypoints, vertices,
//                               per-term costs, per-view reprojection RMS and IoU,
//                               iterations, seconds, convergence, and the errors
//                               against ground truth when the capture has it
//   <out>/summary.json          settings, mean errors (MPJPE, MPVPE, root-relative,
//                               PA with scale, PCK/AUC 0-20 mm as POEM), timings
// Frames run in parallel (TBB) on up to `num_threads` threads; each frame's result
// depends only on its inputs, so the output is the same for any thread count.

#include <string>
#include <vector>

#include "core/hand_model.h"
#include "fitting/ceres_hand_fitter.h"

namespace handlabel {

struct FitCaptureOptions {
  std::string capture_dir;  // capture in the native layout
  std::string out_dir;      // created
  // Frame ids to fit; empty = all (after max_frames).
  std::vector<std::string> frames;
  // Fit at most this many frames (the first ones); 0 = no limit.
  int max_frames = 0;
  // Start: "triangulate" (the baseline: robust triangulation + IK-style alignment),
  // "gt" (ground-truth parameters, for refinement checks), "previous" (the previous
  // fitted frame, frames then run in order on one thread), or a folder of per-frame
  // JSON files (<frame>.json, frames/<frame>.json or labels/<frame>.json, with
  // global_orient, hand_pose, betas, transl at the top or under "params").
  std::string init = "triangulate";
  // 2D evidence: "detections" (simulated detector output), "keypoints" (exact
  // projections), or "auto" (detections if the capture has them).
  std::string evidence = "auto";
  // Masks: "detections" (noisy masks), "truth", "none", or "auto" (detections, else
  // truth, else none).
  std::string masks = "auto";
  // Camera names whose keypoints and masks are ignored (a broken or occluded camera).
  std::vector<std::string> ignore_views;
  HandFitConfig config;
  HandFitOptions fit;
  int num_threads = 1;  // frames in parallel; 0 = all cores
  // If set, a PNG of the first fitted frame (pipeline/fit_overlay.h) is written here.
  std::string overlay_png;
  // Throws InputError naming the flag.
  void Check() const;
};

struct FitCaptureSummary {
  int frames = 0;
  int converged = 0;
  bool has_ground_truth = false;
  double mean_seconds = 0.0;
  double mpjpe = 0.0, mpvpe = 0.0, pa_mpjpe = 0.0, pa_mpvpe = 0.0;  // metres
  double rr_mpjpe = 0.0, rr_mpvpe = 0.0;
  double auc_joints = 0.0;               // PCK AUC 0-20 mm over keypoints
  double max_limit_violation_deg = 0.0;  // largest over frames
  std::string summary_path;
};

FitCaptureSummary FitCapture(const FitCaptureOptions& options, const HandModel& model);

}  // namespace handlabel
