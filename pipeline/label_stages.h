#pragma once
// The stages a labeling job is made of, as small interfaces (the network stage as a
// value), so that the runner (label_job.h) does not depend on how frames are read
// (capture/frame_source.h), how the network predicts or how the fitter fits.
// pipeline/label_stage_factory.h builds them from a job (capture readers, the POEM
// network, the Ceres fitter); tests pass their own.
//
// Every point is in the rig's world frame (metres); 2D keypoints are distorted pixels
// in the full image. Keypoints are in the 21-point SNAP order (hand/hand_model.h).

#include <Eigen/Core>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "capture/frame_source.h"
#include "core/stage_times.h"
#include "geometry/rig.h"
#include "hand/hand_lbs.h"
#include "image/distance_transform.h"

namespace handlabel {

// The network's answer for one frame.
struct MeshPrediction {
  Points3d vertices;                      // V x 3
  Points3d keypoints;                     // 21 x 3
  std::vector<Keypoints2d> keypoints_2d;  // one per rig camera: the network's own 2D
  std::optional<HandParams> params;       // when the network regresses them
  // One per rig camera: the network's hand silhouette in the full image (255 = hand;
  // a 0 x 0 mask where it found none); empty when the network has no mask head or
  // the job does not fit to its masks.
  std::vector<MaskImage> masks;
};

// The network stage: the network's answer per frame in the rig's conventions. A value
// rather than a class to derive from: the one network interface is
// network/poem/hand_mesh_predictor.h, pipeline/network_stage.h makes this stage from it,
// and tests set their own `predict`.
struct NetworkStage {
  std::string model_name;       // recorded in provenance and logs
  std::string weights_sha256;   // SHA-256 of the weights file (recorded in every label)
  bool predicts_masks = false;  // predictions carry silhouettes (MeshPrediction::masks)
  int64_t num_parameters = 0;   // the network's learned parameters (0: unknown)
  int lanes = 1;                // batches the runner may predict at once
  int threads_per_batch = 0;    // the network's own threads per batch (0: unknown)
  // How the answers' 3D keypoints are read (network.keypoints), as the job's start
  // line shows it; empty = the network's joints, unannounced.
  std::string keypoints;
  // network.precision: auto, as the start line shows it ("auto: bf16, the CPU has a
  // bf16 unit"); empty otherwise (the model name carries a precision other than fp32).
  std::string precision;
  // One batch; called by up to `lanes` threads at once (each may use threads itself).
  // Returns one prediction per frame, in order. Throws if the whole batch fails; the
  // runner then retries the frames one by one so that one bad frame fails alone.
  std::function<std::vector<MeshPrediction>(const std::vector<const FrameInput*>&)>
      predict;
};

struct LabelFitRequest {
  const FrameInput* frame = nullptr;
  // The network's mesh to start from (refine), or nullptr: fit from the 2D evidence
  // alone (fallback fit and the fit-only baseline).
  const MeshPrediction* init = nullptr;
  // 2D evidence, one entry per rig camera (job field evidence.keypoints_2d).
  std::vector<std::optional<Keypoints2d>> keypoints_2d;
  // How many of those views hold 2D from files or the detector rather than the
  // network's own 2D. With any, refinement treats the network's answer as a start to
  // check against them, not as evidence of its own (ceres_label_fitter.h).
  int file_views = 0;
  // Silhouettes to fit to instead of the capture's mask files, one per rig camera
  // (evidence.masks: network); empty = the fitter's own choice.
  std::vector<MaskImage> masks;
  // The previous frame's label parameters (job field fit.init: previous), or nullptr.
  const HandParams* previous = nullptr;
  uint64_t seed = 0;
};

struct LabelFit {
  HandParams params;
  HandMesh mesh;
  nlohmann::json
      report;  // solver summary (cost, iterations, ...), written into the label
  // Where the fit's time went, wall seconds per stage (core/stage_times.h), for the
  // job's stage times; never written into the label (labels of identical runs are
  // identical). Empty when the fitter does not say.
  StageSeconds stage_seconds;
};

class LabelFitter {
 public:
  virtual ~LabelFitter() = default;
  // Thread-safe (called concurrently for different frames). Throws when the fit fails.
  virtual LabelFit Fit(const LabelFitRequest& request) const = 0;
  virtual std::string Describe() const = 0;
};

}  // namespace handlabel
