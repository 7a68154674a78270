#pragma once
// `handlabel fit`: the paper's "Multi-view Fit." baseline on a capture in the native
// layout, as a labeling job without a network (refine always from the capture's 2D
// keypoints and masks). The command's flags become a JobConfig (FitJob) and the job
// runner labels the frames, so `fit` and a network-free `label` job with the same
// fields write byte-identical labels. Outputs are the job's (pipeline/label_outputs.h):
//   <out>/labels/<frame>.json   the label: MANO parameters, keypoints, vertices and the
//                               fitter's report (term costs, per-view reprojection RMS
//                               and IoU, iterations, convergence)
//   <out>/summary.json, .md     frames, paths, timings and, when the capture has ground
//                               truth, mean MPJPE, PA-MPJPE, MPVPE, PA-MPVPE, AUC 0-20 mm
// Frames run in parallel (TBB) on up to `num_threads` threads; each label depends only
// on its frame, so the output is the same for any thread count.

#include <ostream>
#include <string>
#include <vector>

#include "pipeline/job_config.h"
#include "pipeline/label_summary.h"

namespace handlabel {

struct FitCaptureOptions {
  std::string capture_dir;  // capture in the native layout (job input.path)
  std::string out_dir;      // created (job output.dir)
  // Frame ids to fit; empty = all (input.frames).
  std::vector<std::string> frames;
  // Fit at most this many frames (the first ones); 0 = no limit (input.max_frames).
  int max_frames = 0;
  // 2D evidence: "detections", "keypoints" (exact projections) or "auto" (detections
  // if the capture has them): evidence.keypoint_files.
  std::string evidence = "auto";
  // Masks: "detections" (noisy masks), "truth", "none", or "auto" (detections, else
  // truth, else none): evidence.mask_files, or evidence.masks none.
  std::string masks = "auto";
  // Object masks as occluders: "files" (where the capture has them) or "none"
  // (evidence.object_masks).
  std::string object_masks = "files";
  // Camera names whose keypoints and masks are ignored (evidence.ignore_views).
  std::vector<std::string> ignore_views;
  // Model file or "capsule"; empty = $HANDLABEL_HAND_MODEL, then the shipped open hand.
  std::string hand_model;
  // Start, loss, sigmas, PCA, limits, shape (section `fit`; unset = the fitter's).
  FitSettings fit;
  int num_threads = 1;    // frames in parallel; 0 = all cores (network.threads)
  bool overlays = false;  // the job's overlay pictures of every label (output.overlays)
  // Throws InputError naming the flag.
  void Check(const std::string& source) const;
};

// The job the options describe (refine always, no network, evidence from files).
JobConfig FitJob(const FitCaptureOptions& options);

struct FitCaptureSummary {
  LabelSummary job;  // the job's summary (also in summary.json)
  int frames = 0;
  int converged = 0;  // fits whose last stage met a Ceres tolerance
  bool has_ground_truth = false;
  double mean_seconds = 0.0;                                        // per frame
  double mpjpe = 0.0, mpvpe = 0.0, pa_mpjpe = 0.0, pa_mpvpe = 0.0;  // metres
  double auc_joints = 0.0;               // PCK AUC 0-20 mm over keypoints
  double max_limit_violation_deg = 0.0;  // largest over the labels
  std::string summary_path;
  std::string hand_model_note;  // ResolveHandModel's note, "" if nothing to say
};

// Runs FitJob(options) (every chosen frame is fitted again) and reads the numbers of
// the baseline back from its labels. `log`: the job's progress and summary lines.
FitCaptureSummary FitCapture(const FitCaptureOptions& options,
                             std::ostream* log = nullptr);

}  // namespace handlabel
