#pragma once
// Temporal fitting over a sequence (issue 45): per-frame fits jitter because each frame
// is solved alone and re-estimates the shape. The smoother
//   1. estimates ONE shape for the sequence (SequenceShape): the betas whose bone
//      lengths match the median over the frames of the per-frame fits' bone lengths
//      (20 bones of the 21 keypoints); the median ignores the frames whose fit went
//      wrong, and the shape is then held fixed, so bones keep their length over time;
//   2. refits windows of consecutive frames jointly (SmoothWindow): one Ceres problem
//      per window with every frame's global_orient, hand_pose and transl, the shape
//      fixed, each frame's 2D keypoint reprojection term exactly as the per-frame fit
//      has it (same robust loss, sigma, joint limits and pose prior folded in), and the
//      keypoint acceleration prior (fitting/acceleration_cost.h) between consecutive
//      frames. Silhouettes are not refitted (the per-frame labels that start the
//      windows carry what they gave).
// With a model of where the 2D detector puts its keypoints (hand/detector_keypoints.h)
// the keypoint terms compare the detector's keypoints of the hand with the 2D, and the
// shape is fitted to the evidence of frames spread over the sequence
// (SequenceShapeFromEvidence) instead of read off the per-frame labels' bones, whose
// lengths are the detector's, not the hand's.
// How windows overlap and blend, and which frames they cover, is the job's business
// (pipeline/smooth_job.h). Units: metres, radians, pixels; frames are assumed equally
// spaced in time.

#include <optional>
#include <string>
#include <vector>

#include "fitting/ceres_hand_fitter.h"
#include "hand/detector_keypoints.h"

namespace ceres {
class Problem;
}

namespace handlabel {

// How the smoother weighs motion against evidence (what is fitted: HandFitConfig,
// whose pose_pca_comps must be 0 and whose joint limits / pose prior are used as in the
// per-frame fit; keypoint loss and sigma: HandFitOptions).
struct SequenceSmoothOptions {
  // Keypoint acceleration per residual unit, mm/frame^2 (> 0). Smaller smooths more.
  // It is per frame^2: the same motion at twice the frame rate accelerates 4x less per
  // frame^2, so scale it with (30 / fps)^2. Chosen on synthetic sequences,
  // docs/fitting.md.
  double acceleration_sigma_mm = 1.0;
  // Ceres iterations per window (>= 1).
  int iterations = 50;
  // Frames whose poses the shape estimate evaluates the bone lengths at (>= 1; tips
  // move a little with the pose through the pose blend shapes), or, with a detector
  // keypoint model, whose evidence the shape is fitted to.
  int shape_frames = 16;
  // Bone length per residual unit of the shape estimate, mm (> 0).
  double bone_sigma_mm = 1.0;
  // Throws InputError naming `source` and the field.
  void Check(const std::string& source) const;
};

// One frame of a window: its 2D evidence and where the solve starts (a per-frame fit).
struct SmoothFrame {
  std::vector<KeypointView> views;  // may be empty: the motion prior carries the frame
  HandParams start;
};

struct SmoothWindowResult {
  std::vector<HandParams> params;  // one per frame, betas = the shape given
  int iterations = 0;
  bool converged = false;
  double initial_cost = 0;  // Ceres cost (0.5 sum of squares) at the start and end
  double final_cost = 0;
};

class SequenceSmoother {
 public:
  // Throws InputError when the options or config do not fit the model (PCA pose) or
  // the detector keypoint model another topology. `detector`: where the 2D evidence's
  // keypoints lie on the hand; nullopt: at the model's keypoints.
  SequenceSmoother(const HandModel& model, const HandFitConfig& config,
                   const HandFitOptions& fit, const SequenceSmoothOptions& options,
                   std::optional<DetectorKeypointModel> detector = std::nullopt);

  const HandEvaluator& evaluator() const { return evaluator_; }
  bool has_detector_model() const { return detector_.has_value(); }

  // The sequence's betas (10) from per-frame fits: their 21 keypoints each, and their
  // parameters (the poses the bone lengths are evaluated at), one per frame, >= 1.
  Eigen::VectorXd SequenceShape(const std::vector<Points3d>& keypoints,
                                const std::vector<HandParams>& params) const;

  // The sequence's betas (10) fitted to the 2D evidence of frames (at least one; any
  // order, e.g. spread over the sequence) jointly: one shape, each frame's pose and
  // place, the per-frame fit's keypoint term and priors (the shape prior once per
  // frame), the frames' `start` as the start. Deterministic as SmoothWindow.
  Eigen::VectorXd SequenceShapeFromEvidence(const std::vector<SmoothFrame>& frames) const;

  // Joint solve of consecutive frames with the shape held at `betas`. Deterministic:
  // one thread, the same inputs give the same bits.
  SmoothWindowResult SmoothWindow(const std::vector<SmoothFrame>& frames,
                                  const Eigen::VectorXd& betas) const;

 private:
  struct FrameBlocks;  // one frame's optimised parameter blocks
  // Adds the frame's blocks (started at frame.start) and its keypoint term with the
  // priors folded in; `shape` is the shared betas block, already in the problem.
  void AddFrame(const SmoothFrame& frame, FrameBlocks* blocks, double* shape,
                ceres::Problem* problem) const;

  HandModel model_;
  HandFitConfig config_;
  HandFitOptions fit_;
  SequenceSmoothOptions options_;
  HandEvaluator evaluator_;
  HandAnatomy anatomy_;
  HandLimits limits_;
  std::optional<DetectorKeypointModel> detector_;
};

}  // namespace handlabel
