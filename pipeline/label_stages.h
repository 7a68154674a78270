#pragma once
// The stages a labeling job is made of, as small interfaces, so that the runner
// (label_job.h) does not depend on how frames are read, how the network predicts or
// how the fitter fits. Implementations: pipeline/label_stage_factory.h builds them from
// a job (capture readers, the POEM network, the Ceres fitter); tests pass their own.
//
// Every point is in the rig's world frame (metres); 2D keypoints are distorted pixels
// in the full image. Keypoints are in the 21-point SNAP order (core/hand_model.h).

#include <Eigen/Core>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/distance_transform.h"
#include "core/hand_lbs.h"
#include "core/rig.h"

namespace handlabel {

// One view's 2D keypoints.
struct Keypoints2dView {
  Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor> uv_px =
      Eigen::Matrix<double, kNumHandKeypoints, 2, Eigen::RowMajor>::Zero();
  // Per keypoint, in [0, 1]; 0 = not detected.
  Eigen::Matrix<double, kNumHandKeypoints, 1> confidence =
      Eigen::Matrix<double, kNumHandKeypoints, 1>::Zero();
};

struct FrameGroundTruth {
  Points3d keypoints;                // 21 x 3
  Points3d vertices;                 // V x 3, or empty when the capture has none
  std::optional<HandParams> params;  // when the capture has them
};

// Everything the capture holds about one multi-view frame. Images and masks stay on
// disk: the stages that need them read them.
struct FrameInput {
  std::string id;
  Rig rig;
  std::vector<std::string> image_paths;  // one per rig camera
  std::vector<std::string> mask_paths;   // one per rig camera, or empty
  // 2D keypoints from files, one entry per rig camera (nullopt: none for that view);
  // empty when the capture has no keypoint files.
  std::vector<std::optional<Keypoints2dView>> keypoints_2d;
  std::optional<FrameGroundTruth> ground_truth;
};

// The network's answer for one frame.
struct MeshPrediction {
  Points3d vertices;                          // V x 3
  Points3d keypoints;                         // 21 x 3
  std::vector<Keypoints2dView> keypoints_2d;  // one per rig camera: the network's own 2D
  std::optional<HandParams> params;           // when the network regresses them
  // One per rig camera: the network's hand silhouette in the full image (255 = hand;
  // a 0 x 0 mask where it found none); empty when the network has no mask head.
  std::vector<MaskImage> masks;
};

class FrameSource {
 public:
  virtual ~FrameSource() = default;
  // Every frame id of the capture, sorted; ids are file-name safe (see label_record.h).
  virtual std::vector<std::string> FrameIds() const = 0;
  // Thread-safe. Throws (InputError for bad files) when the frame cannot be read; the
  // runner records the message as the frame's failure reason.
  virtual FrameInput Load(const std::string& id) const = 0;
  // One line for logs ("native capture /data/cap1, 8 cameras, 1200 frames").
  virtual std::string Describe() const = 0;
  // Which hand the capture shows, when it says (the hand model is built for it);
  // nullopt: the right hand.
  virtual std::optional<HandSide> Side() const { return std::nullopt; }
};

class MeshPredictor {
 public:
  virtual ~MeshPredictor() = default;
  virtual std::string ModelName() const = 0;
  // SHA-256 of the weights file (recorded in every label).
  virtual std::string WeightsSha256() const = 0;
  // True when predictions carry silhouettes (MeshPrediction::masks).
  virtual bool PredictsMasks() const { return false; }
  // One batch; called by one thread at a time (it may use threads itself). Returns one
  // prediction per frame, in order. Throws if the whole batch fails; the runner then
  // retries the frames one by one so that one bad frame fails alone.
  virtual std::vector<MeshPrediction> Predict(
      const std::vector<const FrameInput*>& frames) = 0;
};

struct LabelFitRequest {
  const FrameInput* frame = nullptr;
  // The network's mesh to start from (refine), or nullptr: fit from the 2D evidence
  // alone (fallback fit and the fit-only baseline).
  const MeshPrediction* init = nullptr;
  // 2D evidence, one entry per rig camera (job field evidence.keypoints_2d).
  std::vector<std::optional<Keypoints2dView>> keypoints_2d;
  // Silhouettes to fit to instead of the capture's mask files, one per rig camera
  // (evidence.masks: network); empty = the fitter's own choice.
  std::vector<MaskImage> masks;
  uint64_t seed = 0;
};

struct LabelFit {
  HandParams params;
  HandMesh mesh;
  nlohmann::json
      report;  // solver summary (cost, iterations, ...), written into the label
};

class LabelFitter {
 public:
  virtual ~LabelFitter() = default;
  // Thread-safe (called concurrently for different frames). Throws when the fit fails.
  virtual LabelFit Fit(const LabelFitRequest& request) const = 0;
  virtual std::string Describe() const = 0;
};

}  // namespace handlabel
