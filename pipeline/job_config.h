#pragma once
// A labeling job, as read from its YAML file (jobs/*.yaml; every field is described in
// docs/labeling-jobs.md). Relative paths are resolved against the job file's folder.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "hand/mesh_keypoints.h"

namespace handlabel {

enum class RefineMode { kOff, kAlways, kFallback };
enum class KeypointSource { kNetwork, kFiles, kBoth };
enum class MaskSource { kNone, kFiles, kNetwork };

// The two tunable thresholds were chosen from the ROC of each check against the
// answer's MPJPE (Youden's J for "MPJPE > 8 mm", `compare` on 400 network answers of
// the shipped network, synthetic seeds 3030 with objects + 3031 without; judged on
// seeds 4040 / 4041: docs/comparison.md). They were 12 px and 15 mm before.
struct QualityThresholds {
  // Largest RMS distance (pixels, in the full image) between the network mesh's
  // keypoints projected into a view and the network's own 2D keypoints in that view.
  double max_reprojection_px = 12.3;
  // Largest distance (mm) between the triangulated 2D keypoints and the mesh keypoints.
  double max_view_disagreement_mm = 6.1;
  // Where the frame has 2D keypoints from files (a detector's) and the job uses them
  // (evidence.keypoints_2d files or both): largest median over those views of the RMS
  // pixel distance between the answer's projected keypoints and the files' keypoints
  // (check detector_agreement). Chosen on the real capture's held-out frames
  // (docs/adapt.md).
  double max_detector_rms_px = 12;
  // Views whose keypoint confidence is below this do not count as evidence.
  double min_confidence = 0.3;
  // Fewest views with the hand visible for a frame to be labelled at all.
  int min_views = 2;
  // Plausible hand span (largest distance between two of the 21 keypoints, metres);
  // outside it the network's answer is rejected as out of range.
  double min_hand_span_m = 0.05;
  double max_hand_span_m = 0.35;
};

// Section `fit`: how the fitter fits (refine and fallback fits alike). Every optional
// field left unset keeps the fitter's default (fitting/ceres_hand_fitter.h, where each
// default is explained); `handlabel fit` sets these from its flags.
struct FitSettings {
  // Start of a fit from 2D evidence alone (fallback fit, fit-only job, baseline):
  // "triangulate" (robust triangulation of the 2D keypoints + IK alignment, the paper's
  // baseline), "gt" (the capture's ground-truth parameters, for refinement checks),
  // "previous" (the label of the previous frame in the job's frame order, with a
  // temporal pull; frames then run in order on one thread), or a folder of per-frame
  // parameter files (<frame>.json, frames/<frame>.json or labels/<frame>.json: labels
  // of a job, or global_orient, hand_pose, betas, transl at the top or under "params").
  std::string init = "triangulate";
  std::optional<std::string> keypoint_loss;   // robust loss: cauchy | huber | trivial
  std::optional<double> keypoint_loss_scale;  // in units of keypoint_sigma_px, > 0
  std::optional<double> keypoint_sigma_px;    // keypoint error per residual unit, > 0
  std::optional<double> silhouette_sigma_px;  // silhouette error per residual unit, > 0
  std::optional<int> silhouette_rounds;       // outline re-matching rounds, >= 0
  // Largest per-view mask margin taken out (HandFitOptions::mask_margin_max_px), px,
  // >= 0 (0 = off).
  std::optional<double> mask_margin_px;
  std::optional<int> pose_pca_comps;   // 0 (45 axis-angle values), 12 or 45
  std::optional<bool> joint_limits;    // anatomical joint limits
  std::optional<bool> optimise_shape;  // false: betas stay at the start's
  // Keep a silhouette fit only if it agrees with the keypoints-only fit (quality check
  // silhouette conflict, pipeline/quality_checks.h); false: always keep it.
  std::optional<bool> silhouette_check;
  // Silhouettes where object masks are not used (evidence.object_masks: none):
  // "two_sided" (the full term, guarded by the silhouette check; the default) or
  // "one_sided" (only observed hand pixels must be covered).
  std::optional<std::string> unknown_occluders;
  // Where the 2D keypoints lie on the hand (hand/detector_keypoints.h): "none",
  // "mediapipe" (the shipped model of MediaPipe Hands' keypoints) or a model file. With
  // a model every fit's keypoint term compares the detector's keypoints of the hand with
  // the 2D, so the labels' joints and bones are the hand's, not the detector's.
  std::optional<std::string> detector_keypoints;

  // True when nothing differs from the defaults (the job hash then leaves `fit` out,
  // so jobs written before the section existed keep their hash).
  bool IsDefault() const;
};

// Section `sequence` (docs/labeling-jobs.md "Sequences"): the job's frames are a
// recording, and a smoothing pass (pipeline/smooth_job.h) refits the per-frame labels
// over time into <output.dir>/smoothed/: one shape for the whole sequence, windows of
// consecutive frames solved jointly with a keypoint acceleration prior, blended on
// their overlaps. It never changes the per-frame labels (nor the job hash).
struct SequenceSettings {
  // Run the smoothing pass: `label` runs it after a whole-job run (no --shard),
  // `handlabel smooth --job` at any time after the per-frame labels exist.
  bool smooth = false;
  // Frames per window (>= 3) and frames shared by neighbouring windows (>= 1, at most
  // half a window, so every frame lies in at most two windows' blend).
  int window = 48;
  int overlap = 16;
  // Keypoint acceleration per residual unit, mm/frame^2 (> 0; smaller smooths more;
  // fitting/sequence_smoother.h).
  double acceleration_sigma_mm = 1.0;
  // Ceres iterations per window (>= 1).
  int iterations = 50;
  // Where the 2D evidence's keypoints lie on the hand (hand/detector_keypoints.h):
  // "none" (at the model's keypoints), "mediapipe" (the shipped model of MediaPipe
  // Hands' keypoints, models/detector_keypoints_mediapipe.json) or a model file. With a
  // model the sequence's shape is fitted to the evidence of frames spread over the job
  // and the windows compare the detector's keypoints of the hand with the 2D; the
  // per-frame labels are not affected.
  std::string detector_keypoints = "none";
  // Throws InputError naming the file and the field.
  void Check(const std::string& source) const;
};

struct JobConfig {
  std::string source_file;  // the YAML file (for error messages)
  std::string name = "job";
  uint64_t seed = 0;  // recorded in every label; drives any randomness

  // input
  std::string input_format = "native";  // native | dexycb | ho3d | oakink
  std::string input_path;
  std::string frames = "all";  // "all", "a:b" (half-open index range) or "id,id,..."
  int max_frames = 0;          // label at most the first N selected frames; 0 = all

  // cameras
  std::string cameras_source = "capture";  // capture | file
  std::string cameras_file;

  // .npz / .pkl, or "capsule" (the built-in capsule hand); empty = $HANDLABEL_HAND_MODEL,
  // else the shipped open hand (pipeline/hand_model_source.h).
  std::string hand_model;

  // network
  std::string network_weights;  // empty = no network: every frame is fitted
  int batch_size = 4;
  int threads = 0;  // 0 = all cores
  // network.precision: fp32 | bf16 | auto (HandMeshPredictorOptions::precision).
  std::string network_precision = "fp32";
  // network.keypoints: how the answer's 3D keypoints are read (joints | mesh | mean,
  // hand/mesh_keypoints.h); they are what the quality checks judge and what a kept
  // answer's label carries.
  AnswerKeypoints network_keypoints = AnswerKeypoints::kMean;

  // refinement and fallback
  RefineMode refine_mode = RefineMode::kFallback;
  QualityThresholds quality;
  // Refining a network answer where the frame has file (detector) 2D: the pull of the
  // answer's keypoints (refine.network_sigma_mm, mm per residual unit) and the start's
  // worst-view reprojection error beyond which the fit also runs from the triangulated
  // views (refine.restart_px, px; 0 = always); pipeline/ceres_label_fitter.h.
  double refine_network_sigma_mm = 20;
  double refine_restart_px = 40;
  KeypointSource keypoints = KeypointSource::kNetwork;
  MaskSource masks = MaskSource::kFiles;
  // Which files of a native capture are the file evidence: keypoint_files "auto"
  // (detections if the capture has them, else keypoints), "detections" or "keypoints"
  // (exact projections); mask_files "auto" (detection masks, else true masks),
  // "detections" or "truth". Other input formats take "auto" only.
  std::string keypoint_files = "auto";
  std::string mask_files = "auto";
  // evidence.object_masks: files (default: where the capture has object masks, pixels
  // behind objects do not count against the silhouette fit) | none.
  bool object_masks = true;
  // evidence.detections: a folder of 2D detections in the native format, <frame
  // id>.json per frame (capture/detections_frame_source.h; `handlabel detect` writes
  // them): the job's 2D keypoints, replacing the capture's. Required for input
  // formats without 2D keypoints (ho3d, oakink, dexycb without labels files): a job
  // never runs from no 2D. Empty = the capture's own 2D.
  std::string detections;
  // evidence.keypoints_2d: detector: the 2D keypoints come from MediaPipe Hands run on
  // each frame's images in the job (pipeline/detect_frame_source.h), as `handlabel
  // detect` would write them; they then count as file evidence (keypoints = kFiles).
  bool keypoints_from_detector = false;
  // evidence.detector_model: full | lite (MediaPipe's two model sizes).
  std::string detector_model = "full";
  // evidence.detector_palm_tiles: auto | off | N, palm detection also over N overlapping
  // tiles across each view's shorter side, for small hands
  // (MediapipeHandsOptions::palm_tiles; auto: tiles only on views wider than 1280 px).
  std::string detector_palm_tiles = "auto";
  // evidence.detector_every: N > 1 tracks the hand (with keypoints_2d: detector, a
  // network and refine fallback; pipeline/label_job.h): the detector runs on every
  // N-th frame of the job, on a shard's first frame, after a frame without a label and
  // on frames whose network answer, cut around the previous frame's label, fails its
  // checks; 1 = on every frame.
  int detector_every = 1;
  // evidence.detector_mode: video (with keypoints_2d: detector): the job's frames are
  // detected in order, each frame's regions from the previous frame's 3D hand, palm
  // detection only on a run's first frame, every detector_palm_every-th frame of the job
  // and where the track is lost (DetectHandInVideo); "frame" (false): every frame
  // from scratch.
  bool detector_video = false;
  // evidence.detector_palm_every: with detector_mode video, the job's frame positions
  // (input.frames order) that start a run; 0 = only a shard's first frame and gaps.
  int detector_palm_every = 30;
  // evidence.detector_max_hands: N > 1 (with keypoints_2d: detector, detector_mode
  // frame) looks for up to N hands per frame (MultiViewDetectorOptions::max_hands); the
  // job fits the hand of the capture's side among them (HandIndexOfSide) and says which
  // in the frame log. 1 = the hand most views confirm.
  int detector_max_hands = 1;
  // Camera names whose 2D keypoints and masks are not fitted to (a broken camera).
  std::vector<std::string> ignore_views;
  // Silhouette residual scale (pixels per unit) for the network's masks. In the file
  // 0 (the default) means: 2 px when the network's own 2D keypoints are the only
  // evidence (they are weak, the masks help), else 16 px (good detections: the coarse
  // masks must not pull against them); docs/labeling-jobs.md has the measurements.
  // After loading it holds the resolved value.
  double network_mask_sigma_px = 0;

  // outputs
  std::string output_dir;
  std::vector<std::string> meshes;  // any of "ply", "obj"
  bool overlays = true;
  // Overlay picture files: "jpg" (quality 90; 7.5x smaller than PNG on the demo
  // capture) or "png" (lossless).
  std::string overlay_format = "jpg";
  bool evaluate = true;   // against ground truth, when the capture has it
  bool baseline = false;  // also run the fit-only baseline for comparison

  FitSettings fit;
  SequenceSettings sequence;

  // Throws InputError naming the file and field.
  void Check(const std::string& source) const;
  // Throws InputError naming evidence.keypoints_2d unless a smoothing pass can refit
  // the job's 2D from disk: files, or the in-job detector on every frame (its answers
  // are written beside the labels); not the network's own 2D. Checked on loading a job
  // with sequence.smooth and by `handlabel smooth`.
  void CheckSmoothable() const;
};

// Reads and validates a job file. Unknown keys are errors (they are usually typos).
JobConfig LoadJobConfig(const std::string& path);

std::string ToString(RefineMode mode);

}  // namespace handlabel
