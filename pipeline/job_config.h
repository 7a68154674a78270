#pragma once
// A labeling job, as read from its YAML file (jobs/*.yaml; every field is described in
// docs/labeling-jobs.md). Relative paths are resolved against the job file's folder.

#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

enum class RefineMode { kOff, kAlways, kFallback };
enum class KeypointSource { kNetwork, kFiles, kBoth };
enum class MaskSource { kNone, kFiles, kNetwork };

struct QualityThresholds {
  // Largest RMS distance (pixels, in the full image) between the network mesh's
  // keypoints projected into a view and the network's own 2D keypoints in that view.
  double max_reprojection_px = 12.0;
  // Largest distance (mm) between the triangulated 2D keypoints and the mesh keypoints.
  double max_view_disagreement_mm = 15.0;
  // Views whose keypoint confidence is below this do not count as evidence.
  double min_confidence = 0.3;
  // Fewest views with the hand visible for a frame to be labelled at all.
  int min_views = 2;
  // Plausible hand span (largest distance between two of the 21 keypoints, metres);
  // outside it the network's answer is rejected as out of range.
  double min_hand_span_m = 0.05;
  double max_hand_span_m = 0.35;
};

struct JobConfig {
  std::string source_file;  // the YAML file (for error messages)
  std::string name = "job";
  uint64_t seed = 0;  // recorded in every label; drives any randomness

  // input
  std::string input_format = "native";  // native | dexycb | ho3d | oakink
  std::string input_path;
  std::string frames = "all";  // "all", "a:b" (half-open index range) or "id,id,..."

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

  // refinement and fallback
  RefineMode refine_mode = RefineMode::kFallback;
  QualityThresholds quality;
  KeypointSource keypoints = KeypointSource::kNetwork;
  MaskSource masks = MaskSource::kFiles;
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
  bool evaluate = true;   // against ground truth, when the capture has it
  bool baseline = false;  // also run the fit-only baseline for comparison

  // Throws InputError naming the file and field.
  void Check() const;
};

// Reads and validates a job file. Unknown keys are errors (they are usually typos).
JobConfig LoadJobConfig(const std::string& path);

std::string ToString(RefineMode mode);

}  // namespace handlabel
