#pragma once
// Fits the hand model to multi-view evidence with Ceres: 2D keypoints (with
// confidences, robust loss, lens distortion), silhouettes, anatomical joint limits,
// pose and shape priors, optional 3D targets (the network's keypoints/vertices) and an
// optional pull towards the previous frame. Staged solve:
//   1. rigid     global_orient + transl on the keypoints (pose and shape held)
//   2. keypoints everything on keypoints + limits + priors (+ 3D targets, temporal)
//   3. silhouette everything, with the silhouette term added; outline samples are
//                re-matched to the nearest projected vertex before each round.
// Initialisations: InitFromKeypoints3d (e.g. the network's), InitFromViews (the
// paper's "Multi-view Fit." baseline: robust triangulation of the 2D keypoints, then an
// IK-style alignment), or the previous frame's parameters.
//
// Parameters are MANO's: global_orient (axis-angle, optimised on SO(3) through
// AxisAngleManifold), hand_pose (45 axis-angle values, or pose_pca_comps PCA
// coefficients), the first 10 betas, transl. Units: metres, radians, pixels.

#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/stage_times.h"
#include "fitting/keypoint_view.h"
#include "fitting/points3d_targets.h"
#include "fitting/robust_loss.h"
#include "fitting/silhouette_outline.h"
#include "hand/detector_keypoints.h"
#include "hand/hand_anatomy.h"
#include "hand/hand_evaluator.h"
#include "hand/hand_lbs.h"
#include "hand/hand_model.h"
#include "image/distance_transform.h"
#include "image/rasterizer.h"

namespace handlabel {

// What is optimised and which terms are used (separate from how: HandFitOptions).
struct HandFitConfig {
  // 0: hand_pose is 45 axis-angle values; 12 or 45: that many PCA coefficients of the
  // model's pose basis (the model needs pose_pca_basis). Other values: InputError.
  int pose_pca_comps = 0;
  bool optimise_shape = true;    // false: betas stay at their initial values
  bool use_keypoints = true;     // 2D keypoint reprojection (needs views)
  bool use_silhouettes = true;   // only where masks are given
  bool use_joint_limits = true;  // anatomical hinge limits
  bool use_pose_prior = true;
  bool use_shape_prior = true;
  bool use_points3d = true;  // only if HandFitInput::targets3d is set
  bool use_temporal = true;  // only if HandFitInput::previous is set
  void Check(const std::string& source) const;
};

// How to optimise; every weight is expressed as the standard deviation that one unit
// of residual stands for.
struct HandFitOptions {
  // Keypoint reprojection: error scale (pixels) and per-keypoint robust loss (its
  // scale in units of keypoint_sigma_px). Cauchy at 3 sigma: near least squares for
  // noisy detections, and far outliers lose their pull (with Huber they keep a
  // constant pull that bent joints up to 9 degrees past their limits in our 50-frame
  // test; Cauchy: 1.2 degrees, and lower MPJPE).
  double keypoint_sigma_px = 1.0;
  RobustLoss keypoint_loss{RobustLossType::kCauchy, 3.0};
  // Joint limits: one residual unit per limit_sigma_deg of violation.
  double limit_sigma_deg = 1.0;
  // Pose prior: distance of the 45 axis-angle values to the model's pose_mean, per
  // value (radians). Weak: it only breaks ties the evidence leaves open.
  double pose_prior_sigma_rad = 1.0;
  // Shape prior on betas (unit variance by construction).
  double shape_prior_sigma = 1.0;
  // 3D targets: metres per residual unit.
  double points3d_sigma_m = 0.002;
  // Temporal pull towards HandFitInput::previous (pose: radians, transl: metres).
  double temporal_pose_sigma_rad = 0.2;
  double temporal_transl_sigma_m = 0.02;
  // Silhouettes: pixels per residual unit; vertices used (every n-th); outline
  // samples per view (evenly spaced along the mask outline); match-and-solve rounds.
  double silhouette_sigma_px = 2.0;
  int silhouette_vertex_stride = 2;
  int silhouette_outline_samples = 120;
  int silhouette_rounds = 3;
  // Each view's distance transform covers the hand mask and the projected hand (after
  // the keypoint stages) with this many pixels around them (>= 0); beyond it the
  // distance is extended from the window's border (fitting/silhouette_cost.h). Vertices
  // rarely go that far: the window only bounds the cost of the transform.
  int silhouette_window_margin_px = 24;
  // Outline samples match only vertices whose normal makes |cos| below this with the
  // viewing ray (contour generators).
  double silhouette_contour_cosine = 0.6;
  // Hand mask pixels within this many pixels (Chebyshev) of an occluder pixel are not
  // outline samples: the hand may continue behind the occluder there. It must cover
  // the hand mask's misalignment to the occluder mask (a detector's mask eroded by r
  // pixels leaves a gap of r pixels next to the object); >= 0.
  int occluder_reach_px = 2;
  // Views whose occluders are unknown (HandFitInput::unknown_occluders): the mesh ->
  // mask distance saturates at this many pixels (fitting/silhouette_cost.h), > 0.
  double unknown_occluder_cap_px = 3.0;
  // Per-view mask margin: masks are often uniformly too fat or too thin (a detector's,
  // a segmenter's). Before each silhouette round every two-sided view's margin is
  // estimated from the current fit (EstimateMaskMargin, fitting/silhouette_outline.h),
  // clamped to +-this many pixels, and taken out: outline samples move inwards by it,
  // and an eroded mask's vertices may lie that far outside it. 0 = off; >= 0.
  double mask_margin_max_px = 3.0;
  // Ceres iterations per stage (silhouette: per round).
  int rigid_iterations = 20;
  // The rigid stage is skipped when the start's median keypoint reprojection error
  // over all views is below this (px): a start aligned to this frame's keypoints
  // (InitFromViews) needs no rigid pass. 0 = always run it; >= 0.
  double rigid_skip_below_px = 10.0;
  int keypoint_iterations = 60;
  int silhouette_iterations = 10;
  // Pose-and-shape iterations of the 3D initialisation (InitFromKeypoints3d/Views): it
  // starts from the closed-form bone alignment (fitting/analytic_hand_pose.h), so it
  // needs few iterations to land in the keypoint stages' basin.
  int init_iterations = 20;
  // Ceres convergence tolerances.
  double function_tolerance = 1e-6;
  double parameter_tolerance = 1e-10;
  // Threads Ceres may use inside one frame (frames run in parallel elsewhere).
  int num_threads = 1;
  // Triangulation of the baseline initialisation.
  double triangulation_inlier_px = 10.0;
  // Distance from the first camera used when fewer than 3 palm keypoints triangulate.
  double fallback_depth_m = 0.6;
  // Where the 2D keypoints lie on the hand (hand/detector_keypoints.h): the keypoint
  // term compares the detector's keypoints of the hand (a MediaPipe keypoint is not at
  // the model's joint) with the 2D; nullptr = the model's own keypoints. The fitted
  // hand's joints stay the model's. Checked against the model in the fitter.
  std::shared_ptr<const DetectorKeypointModel> detector_keypoints;
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

struct HandFitInput {
  std::vector<KeypointView> views;  // 2D keypoints per view (may be empty)
  // Per view: silhouette mask (rows = image height), or empty = none for that view.
  // Empty vector = no silhouettes. Cameras come from `views`.
  std::vector<MaskImage> masks;
  // Per view: pixels where something in front of the hand may hide it (255 = an
  // object), or empty = nothing known; empty vector = none. Where given, the hand may
  // project onto these pixels unpenalised and the hand mask's outline next to them is
  // not a hand boundary (docs/fitting.md, "Occlusion").
  std::vector<MaskImage> occluder_masks;
  // True when objects no occluder mask shows may carve the masks (object masks not
  // known). Views without an occluder mask then get the one-sided silhouette term:
  // observed hand pixels must be covered (outline samples pull only outwards), the
  // projected hand may extend beyond the mask (the mesh -> mask half saturates at
  // HandFitOptions::unknown_occluder_cap_px).
  bool unknown_occluders = false;
  std::optional<Points3dTargets> targets3d;
  std::optional<HandParams> previous;
};

// The names of the views that hold a keypoint the fit uses (confidence > 0 and a finite
// position), in the order of `views`.
std::vector<std::string> ViewsWithKeypoints(const std::vector<KeypointView>& views);

// The result of the keypoint stage (before any silhouette round): what the same fit
// without silhouettes gives, kept so that a silhouette fit can be checked against it.
struct HandFitStageResult {
  HandParams params;
  Points3d vertices;                // V x 3, world frame
  Points3d keypoints;               // 21 x 3, SNAP order
  std::vector<double> view_rms_px;  // as HandFitResult::view_rms_px
  std::vector<double> view_iou;     // as HandFitResult::view_iou
};

struct HandFitResult {
  HandParams params;
  Points3d vertices;   // V x 3, world frame
  Points3d keypoints;  // 21 x 3, SNAP order
  // Final cost (0.5 sum of squared residuals) per term: "keypoints", "silhouette",
  // "joint_limits", "pose_prior", "shape_prior", "points3d", "temporal".
  std::map<std::string, double> term_costs;
  // Per view: RMS pixel distance of the detected keypoints (confidence > 0) to the
  // fitted keypoints' projections (NaN without detections); silhouette IoU of the
  // fitted mesh and the mask (NaN without a mask).
  std::vector<double> view_rms_px;
  std::vector<double> view_iou;
  // Per view: the mask margin taken out in the last silhouette round
  // (HandFitOptions::mask_margin_max_px), pixels; NaN where no silhouette was fitted.
  std::vector<double> view_mask_margin_px;
  int iterations = 0;  // Ceres iterations over all stages
  double seconds = 0.0;
  // Where `seconds` went (core/stage_times.h): "setup" (checks, parameter blocks),
  // "rigid", "keypoints" and "silhouettes" (the solves; silhouettes with building their
  // evidence), "evaluate" (the final mesh and its agreement per view).
  StageSeconds stage_seconds;
  bool converged = false;  // the last stage met a Ceres convergence tolerance
  std::string message;     // Ceres' message of the last stage
  // Set when silhouette rounds ran: the keypoints-only result they started from.
  std::optional<HandFitStageResult> keypoints_only;
};

class CeresHandFitter {
 public:
  // Throws InputError if the options, config or model do not fit together.
  CeresHandFitter(const HandModel& model, const HandFitConfig& config = {},
                  const HandFitOptions& options = {});

  const HandEvaluator& evaluator() const { return evaluator_; }
  const HandFitConfig& config() const { return config_; }
  const HandFitOptions& options() const { return options_; }

  // IK-style alignment to 3D keypoints (SNAP order; weight 0 = unknown): rigid
  // alignment of the palm keypoints, then pose and shape on the 3D keypoints with the
  // limits and priors.
  HandParams InitFromKeypoints3d(const Points3d& keypoints,
                                 const Eigen::VectorXd& weights) const;
  // The baseline's start: each keypoint triangulated robustly over the views
  // (geometry/triangulation.h), then InitFromKeypoints3d's closed form (rigid palm
  // alignment + bone alignment) without its pose-and-shape solve: Fit's keypoint stage
  // does that against the 2D keypoints themselves. With a PCA pose (no closed form)
  // or fewer than 3 palm keypoints the 3D solve still runs.
  HandParams InitFromViews(const std::vector<KeypointView>& views) const;

  // Staged solve from `init`. Throws Error when nothing places the hand in depth: 2D
  // keypoints in fewer than 2 views (ViewsWithKeypoints) and neither 3D targets nor a
  // previous frame to pull towards. One view's rays leave the distance free (only the
  // shape prior holds the hand's size): such fits ended metres off with a small
  // reprojection error, so the frame must fail by name instead.
  HandFitResult Fit(const HandFitInput& input, const HandParams& init) const;

 private:
  // The check of Fit's comment.
  void RequireDepthEvidence(const HandFitInput& input) const;

  HandModel model_;
  HandFitConfig config_;
  HandFitOptions options_;
  HandEvaluator evaluator_;
  HandAnatomy anatomy_;
  HandLimits limits_;
};

}  // namespace handlabel
