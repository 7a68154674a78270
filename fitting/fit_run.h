#pragma once
// The staged solve behind CeresHandFitter (fitting/ceres_hand_fitter.h): FitRun<P> runs
// the stages the fitter's header describes (rigid, keypoints, silhouette rounds) over an
// explicit FitState, and the 3D initialisation. Internal to fitting/: only
// ceres_hand_fitter.cc and sequence_smoother.cc include it (it reaches Ceres).

#include <ceres/ceres.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "core/errors.h"
#include "core/stage_times.h"
#include "fitting/analytic_hand_pose.h"
#include "fitting/ceres_hand_fitter.h"
#include "fitting/joint_limit_cost.h"
#include "fitting/keypoint_reprojection_cost.h"
#include "fitting/points3d_cost.h"
#include "fitting/prior_costs.h"
#include "fitting/silhouette_cost.h"
#include "fitting/silhouette_outline.h"
#include "fitting/silhouette_render.h"
#include "fitting/stage_problem.h"
#include "geometry/triangulation.h"

namespace handlabel::fitting_internal {

// The occluder mask of view v, or nullptr when there is none; it must match the hand
// mask's size (a view without a hand mask does not use it).
inline const MaskImage* Occluder(const HandFitInput& input, size_t v) {
  if (v >= input.occluder_masks.size() || input.occluder_masks[v].size() == 0)
    return nullptr;
  const MaskImage& occluder = input.occluder_masks[v];
  if (v < input.masks.size() && input.masks[v].size() > 0 &&
      (occluder.rows() != input.masks[v].rows() ||
       occluder.cols() != input.masks[v].cols())) {
    throw InputError(
        "HandFitInput", "occluder_masks[" + std::to_string(v) + "]",
        "the hand mask's size",
        std::to_string(occluder.cols()) + "x" + std::to_string(occluder.rows()));
  }
  return &occluder;
}

// The window of a view's distance transform: the hand mask's pixels and the projected
// hand (`vertices`, world frame) with `margin_px` around them, inside the image; empty
// when neither is in the image.
inline PixelWindow HandWindow(const MaskImage& mask, const RigCamera& camera,
                              const Points3d& vertices, int margin_px) {
  const int w = static_cast<int>(mask.cols()), h = static_cast<int>(mask.rows());
  int x_min = w, y_min = h, x_max = -1, y_max = -1;
  auto include = [&](double x, double y) {
    x_min = std::min(x_min, static_cast<int>(std::floor(x)));
    y_min = std::min(y_min, static_cast<int>(std::floor(y)));
    x_max = std::max(x_max, static_cast<int>(std::ceil(x)));
    y_max = std::max(y_max, static_cast<int>(std::ceil(y)));
  };
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (mask(y, x) != 0) include(x, y);
    }
  }
  for (Eigen::Index i = 0; i < vertices.rows(); ++i) {
    Eigen::Vector2d uv;
    if (camera.ProjectWorld(vertices.row(i).transpose(), &uv) &&
        uv.cwiseAbs().maxCoeff() < 1e6) {
      include(uv.x(), uv.y());
    }
  }
  PixelWindow window;
  window.x0 = std::max(x_min - margin_px, 0);
  window.y0 = std::max(y_min - margin_px, 0);
  window.width = std::min(x_max + margin_px, w - 1) - window.x0 + 1;
  window.height = std::min(y_max + margin_px, h - 1) - window.y0 + 1;
  return window;
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Squared pixel distances between a view's observed keypoints (confidence > 0) and the
// projections of `keypoints` (world frame); keypoints behind the camera are left out.
inline std::vector<double> KeypointSquaredErrorsPx(const KeypointView& view,
                                                   const Points3d& keypoints) {
  std::vector<double> squared;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (!(view.keypoints.confidence[k] > 0.0)) continue;
    Eigen::Vector2d uv;
    if (!view.camera.ProjectWorld(keypoints.row(k).transpose(), &uv)) continue;
    squared.push_back((uv - view.keypoints.uv_px.row(k).transpose()).squaredNorm());
  }
  return squared;
}
// Palm keypoints (SNAP): wrist and the four finger MCPs; rigid in the hand's frame.
constexpr int kPalmKeypoints[] = {0, 5, 9, 13, 17};

// Least-squares rotation R and translation t with target ~ R * source + t (Kabsch).
inline void RigidAlign(const std::vector<Eigen::Vector3d>& source,
                       const std::vector<Eigen::Vector3d>& target, Eigen::Matrix3d* r,
                       Eigen::Vector3d* t) {
  Eigen::Vector3d ms = Eigen::Vector3d::Zero(), mt = Eigen::Vector3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    ms += source[i];
    mt += target[i];
  }
  ms /= source.size();
  mt /= source.size();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (size_t i = 0; i < source.size(); ++i) {
    cov += (target[i] - mt) * (source[i] - ms).transpose();
  }
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Vector3d sign(1, 1, 1);
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0) sign[2] = -1;
  *r = svd.matrixU() * sign.asDiagonal() * svd.matrixV().transpose();
  *t = mt - *r * ms;
}

inline Eigen::Matrix<double, 45, 1> PoseMean(const HandModel& model) {
  if (model.pose_mean.size() == kNumPoseParams) return model.pose_mean;
  return Eigen::Matrix<double, 45, 1>::Zero();
}

// Throws InputError unless the masks and occluder masks come one per view (or not at
// all).
inline void CheckMaskCounts(const HandFitInput& input) {
  if (!input.masks.empty() && input.masks.size() != input.views.size()) {
    throw InputError("HandFitInput", "masks",
                     std::to_string(input.views.size()) + " masks (one per view) or none",
                     std::to_string(input.masks.size()));
  }
  if (!input.occluder_masks.empty() &&
      input.occluder_masks.size() != input.views.size()) {
    throw InputError("HandFitInput", "occluder_masks",
                     std::to_string(input.views.size()) + " masks (one per view) or none",
                     std::to_string(input.occluder_masks.size()));
  }
}

// What one Fit() carries from stage to stage.
struct FitState {
  explicit FitState(const HandFitInput& input) : input(input) {}
  const HandFitInput& input;
  Blocks blocks;              // the parameters being solved
  Blocks previous;            // input.previous, for the temporal term
  bool use_kp = false;        // 2D keypoints
  bool use_3d = false;        // 3D targets
  bool use_temporal = false;  // pull towards input.previous
  bool use_sil = false;       // silhouettes (some mask, rounds > 0)
  HandFitResult result;       // iterations, term costs etc. of the stages so far
};

// The silhouette term's views (those with a usable mask) and what it matches.
struct SilhouetteEvidence {
  std::vector<int> vertex_ids;  // vertices the term uses (every stride-th)
  std::vector<SilhouetteView> views;
  std::vector<MaskOutline> outlines;  // per view: samples of the mask's outline
  std::vector<size_t> input_view;     // per view: its index in HandFitInput::views
};

// Everything the stages need, templated on the pose block size.
template <int P>
class FitRun {
 public:
  FitRun(const HandModel& model, const HandEvaluator& evaluator,
         const HandAnatomy& anatomy, const HandLimits& limits,
         const HandFitConfig& config, const HandFitOptions& options)
      : model_(model),
        evaluator_(evaluator),
        anatomy_(anatomy),
        limits_(limits),
        config_(config),
        options_(options) {}

  Blocks ToBlocks(const HandParams& p) const {
    Blocks b;
    for (int i = 0; i < 3; ++i) {
      b.orient[i] = p.global_orient[i];
      b.transl[i] = p.transl[i];
    }
    for (int s = 0; s < kBetas; ++s) b.betas[s] = s < p.betas.size() ? p.betas[s] : 0.0;
    if (config_.pose_pca_comps == 0) {
      b.pose.assign(p.hand_pose.data(), p.hand_pose.data() + kNumPoseParams);
    } else {
      // Least-squares coefficients: basis^T c ~ pose - mean.
      const int n = config_.pose_pca_comps;
      const Eigen::MatrixXd basis = model_.pose_pca_basis.topRows(n);
      const Eigen::VectorXd c = (basis * basis.transpose())
                                    .ldlt()
                                    .solve(basis * (p.hand_pose - PoseMean(model_)));
      b.pose.assign(c.data(), c.data() + n);
    }
    return b;
  }

  HandParams FromBlocks(const Blocks& b) const {
    HandParams p;
    p.global_orient = Eigen::Vector3d(b.orient);
    p.transl = Eigen::Vector3d(b.transl);
    p.betas = Eigen::Map<const Eigen::VectorXd>(b.betas, kBetas);
    evaluator_.AxisAnglePose(b.pose.data(), p.hand_pose.data());
    return p;
  }

  // Calls add(name, cost, block) for each prior the config asks for; block indexes the
  // full parameter blocks (orient, pose, betas, transl).
  template <typename Add>
  void ForEachPrior(Add add) const {
    constexpr int kPoseBlock = 1, kBetasBlock = 2;
    if (config_.use_joint_limits) {
      const double w = 1.0 / std::pow(options_.limit_sigma_deg * M_PI / 180.0, 2);
      add("joint_limits", JointLimitCost<P>::Create(evaluator_, anatomy_, limits_, w),
          kPoseBlock);
    }
    if (config_.use_pose_prior) {
      const Eigen::Matrix<double, 45, 1> inv =
          Eigen::Matrix<double, 45, 1>::Constant(1.0 / options_.pose_prior_sigma_rad);
      add("pose_prior", PosePriorCost<P>::Create(evaluator_, PoseMean(model_), inv),
          kPoseBlock);
    }
    if (config_.use_shape_prior) {
      add("shape_prior", ShapePriorCost<kBetas>::Create(options_.shape_prior_sigma),
          kBetasBlock);
    }
  }
  void AddPriors(StageProblem* problem, Blocks* b) const {
    double* blocks[] = {b->orient, b->pose.data(), b->betas, b->transl};
    ForEachPrior([&](const char* name, ceres::CostFunction* cost, int block) {
      problem->Add(name, cost, blocks[block]);
    });
  }

  // Median distance (px) between the observed 2D keypoints and the projections of the
  // hand of `b` over all views; infinity without observations.
  double MedianKeypointErrorPx(const std::vector<KeypointView>& views,
                               const Blocks& b) const {
    Points3d keypoints(kNumHandKeypoints, 3);
    evaluator_.Keypoints(b.orient, b.pose.data(), b.betas, b.transl, keypoints.data());
    std::vector<double> squared;
    for (const KeypointView& view : views) {
      const std::vector<double> view_squared = KeypointSquaredErrorsPx(view, keypoints);
      squared.insert(squared.end(), view_squared.begin(), view_squared.end());
    }
    if (squared.empty()) return std::numeric_limits<double>::infinity();
    auto middle = squared.begin() + squared.size() / 2;
    std::nth_element(squared.begin(), middle, squared.end());
    return std::sqrt(*middle);
  }

  // 3D targets as the only evidence: the IK-style initialisation.
  void SolvePoints3d(const Points3dTargets& targets, Blocks* b, bool full) const {
    for (int stage = 0; stage < (full ? 2 : 1); ++stage) {
      StageProblem problem(b);
      // Keypoints only (the initialisation): the analytic Jacobian is much cheaper.
      problem.AddFull("points3d",
                      targets.vertex_ids.empty()
                          ? Keypoints3dCostFunction::Create(evaluator_, targets.keypoints,
                                                            targets.keypoint_weights,
                                                            options_.points3d_sigma_m)
                          : Points3dCost<P, kBetas>::Create(evaluator_, targets,
                                                            options_.points3d_sigma_m));
      if (stage == 0) {
        problem.Hold(b->pose.data());
        problem.Hold(b->betas);
      } else {
        AddPriors(&problem, b);
        if (!config_.optimise_shape) problem.Hold(b->betas);
      }
      problem.Solve(SolverOptions(
          options_, stage == 0 ? options_.rigid_iterations : options_.init_iterations));
    }
  }

  // The staged solve of fitting/ceres_hand_fitter.h from `init`.
  HandFitResult Fit(const HandFitInput& input, const HandParams& init) const {
    const auto start = std::chrono::steady_clock::now();
    CheckMaskCounts(input);
    FitState state = StartFit(input, init);
    StageSeconds& times = state.result.stage_seconds;
    times["setup"] = SecondsSince(start);
    {
      StageTimer timer(&times, "rigid");
      SolveRigid(&state);
    }
    {
      StageTimer timer(&times, "keypoints");
      SolveKeypoints(&state);
    }
    {
      StageTimer timer(&times, "silhouettes");
      SolveSilhouettes(&state);
    }
    const auto end = std::chrono::steady_clock::now();
    HandFitResult result = MakeResult(&state, start);
    result.stage_seconds["evaluate"] = SecondsSince(end);
    return result;
  }

  // The silhouette rounds after the keypoint fit (none without masks).
  void SolveSilhouettes(FitState* state) const {
    SilhouetteEvidence silhouettes = BuildSilhouetteViews(*state);
    state->result.view_mask_margin_px.assign(state->input.views.size(), kNaN);
    // What the same fit without silhouettes gives, to check the silhouette fit against.
    if (!silhouettes.views.empty()) {
      state->result.keypoints_only = Evaluate(state->input, FromBlocks(state->blocks));
    }
    for (int round = 0; !silhouettes.views.empty() && round < options_.silhouette_rounds;
         ++round) {
      SolveSilhouetteRound(&silhouettes, state);
    }
  }

  // The posed hand of `params` and its agreement with the evidence per view.
  HandFitStageResult Evaluate(const HandFitInput& input, const HandParams& params) const {
    HandFitStageResult out;
    out.params = params;
    const HandMesh mesh = PoseHand(model_, params);
    out.vertices = mesh.vertices;
    out.keypoints = mesh.keypoints;
    for (const KeypointView& view : input.views) {
      const std::vector<double> squared = KeypointSquaredErrorsPx(view, mesh.keypoints);
      double sum = 0.0;
      for (double e : squared) sum += e;
      out.view_rms_px.push_back(squared.empty() ? kNaN : std::sqrt(sum / squared.size()));
    }
    out.view_iou.assign(input.views.size(), kNaN);
    for (size_t v = 0; v < input.masks.size(); ++v) {
      if (input.masks[v].size() == 0) continue;
      out.view_iou[v] =
          ProjectedMeshIoU(out.vertices, model_.faces, input.views[v].camera,
                           input.masks[v], Occluder(input, v));
    }
    return out;
  }

  // `solve` = false keeps the closed form (rigid palm alignment + bone alignment) where
  // it applies: a keypoint fit follows and refines it anyway.
  HandParams InitFromKeypoints3d(const Points3d& keypoints,
                                 const Eigen::VectorXd& weights,
                                 const Eigen::Vector3d& fallback_position,
                                 bool solve) const {
    HL_CHECK(keypoints.rows() == kNumHandKeypoints && weights.size() == kNumHandKeypoints,
             "21 keypoints and weights");
    Blocks b = ToBlocks(HandParams());
    double rest[3 * kNumHandKeypoints];
    evaluator_.Keypoints(b.orient, b.pose.data(), b.betas, b.transl, rest);
    const Eigen::Vector3d wrist_rest(rest[0], rest[1], rest[2]);
    std::vector<Eigen::Vector3d> source, target;
    for (int k : kPalmKeypoints) {
      if (!(weights[k] > 0.0)) continue;
      source.emplace_back(rest[3 * k], rest[3 * k + 1], rest[3 * k + 2]);
      target.push_back(keypoints.row(k).transpose());
    }
    Eigen::Matrix3d r = Eigen::Matrix3d::Identity();
    Eigen::Vector3d t = fallback_position - wrist_rest;
    int known = 0;
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero(), rest_centroid = centroid;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (!(weights[k] > 0.0)) continue;
      ++known;
      centroid += keypoints.row(k).transpose();
      rest_centroid += Eigen::Vector3d(rest[3 * k], rest[3 * k + 1], rest[3 * k + 2]);
    }
    if (source.size() >= 3) {
      RigidAlign(source, target, &r, &t);
    } else if (known > 0) {
      t = centroid / known - rest_centroid / known;
    }
    // posed = R (p - J0) + J0 + transl = R p + t  =>  transl = t + R J0 - J0.
    const Eigen::AngleAxisd aa(r);
    const Eigen::Vector3d orient = aa.angle() * aa.axis();
    const Eigen::Vector3d transl = t + r * wrist_rest - wrist_rest;
    for (int i = 0; i < 3; ++i) {
      b.orient[i] = orient[i];
      b.transl[i] = transl[i];
    }
    bool closed_form = false;
    if constexpr (P == kNumPoseParams) {
      if (source.size() >= 3) {
        const Points3d rest_points =
            Eigen::Map<const Points3d>(rest, kNumHandKeypoints, 3);
        AnalyticHandPose(rest_points, keypoints, weights, r, b.pose.data());
        closed_form = true;
      }
    }
    if (known >= 4 && (solve || !closed_form)) {
      Points3dTargets targets;
      targets.keypoints = keypoints;
      targets.keypoint_weights = weights.cwiseMax(0.0);
      SolvePoints3d(targets, &b, /*full=*/true);
    }
    return FromBlocks(b);
  }

 private:
  // The start's blocks and which terms this input brings.
  FitState StartFit(const HandFitInput& input, const HandParams& init) const {
    FitState s(input);
    s.blocks = ToBlocks(init);
    if (input.previous) s.previous = ToBlocks(*input.previous);
    s.use_kp = config_.use_keypoints && !input.views.empty();
    s.use_3d = config_.use_points3d && input.targets3d.has_value();
    s.use_temporal = config_.use_temporal && input.previous.has_value();
    for (const MaskImage& m : input.masks) s.use_sil |= m.size() > 0;
    s.use_sil &= config_.use_silhouettes && options_.silhouette_rounds > 0;
    return s;
  }

  // The keypoints and 3D targets; with_priors: the priors too, folded into the keypoint
  // term when there is one.
  void AddEvidence(StageProblem* problem, FitState* s, bool with_priors) const {
    if (s->use_kp) {
      auto* keypoints = new MultiViewKeypointSquareRootCost(
          evaluator_, s->input.views, options_.keypoint_loss, options_.keypoint_sigma_px,
          options_.detector_keypoints.get());
      if (with_priors) {
        ForEachPrior([&](const char* name, ceres::CostFunction* cost, int block) {
          keypoints->folded()->Add(name, cost, block);
        });
      }
      problem->AddFull("keypoints", keypoints, keypoints->folded());
    } else if (with_priors) {
      AddPriors(problem, &s->blocks);
    }
    if (s->use_3d) {
      problem->AddFull("points3d",
                       Points3dCost<P, kBetas>::Create(evaluator_, *s->input.targets3d,
                                                       options_.points3d_sigma_m));
    }
  }
  // The pull of pose and transl towards input.previous.
  void AddTemporal(StageProblem* problem, FitState* s) const {
    if (!s->use_temporal) return;
    problem->Add("temporal",
                 ParameterPriorCost<P>::Create(s->previous.pose.data(),
                                               options_.temporal_pose_sigma_rad),
                 s->blocks.pose.data());
    problem->Add("temporal",
                 ParameterPriorCost<3>::Create(s->previous.transl,
                                               options_.temporal_transl_sigma_m),
                 s->blocks.transl);
  }
  // Everything but the silhouettes, pose and shape free: the problem of the keypoint
  // stage, which each silhouette round extends.
  void AddPoseAndShapeTerms(StageProblem* problem, FitState* s) const {
    AddEvidence(problem, s, /*with_priors=*/true);
    AddTemporal(problem, s);
    if (!config_.optimise_shape) problem->Hold(s->blocks.betas);
  }
  // Solves `problem`: iterations add up over the stages; convergence, message and term
  // costs are the last stage's.
  void RunStage(StageProblem* problem, int iterations, HandFitResult* result) const {
    const ceres::Solver::Summary s = problem->Solve(SolverOptions(options_, iterations));
    result->iterations += static_cast<int>(s.iterations.size()) - 1;
    result->converged = IsDone(s);
    result->message = s.message;
    result->term_costs = problem->TermCosts();
  }

  // 1. Rigid: brings a far start (a flat hand, another frame's answer) into the
  // keypoints' basin; a start already aligned to this frame's keypoints skips it.
  void SolveRigid(FitState* s) const {
    if ((s->use_kp || s->use_3d) && options_.rigid_iterations > 0 &&
        !(s->use_kp && MedianKeypointErrorPx(s->input.views, s->blocks) <
                           options_.rigid_skip_below_px)) {
      StageProblem problem(&s->blocks);
      AddEvidence(&problem, s, /*with_priors=*/false);
      problem.Hold(s->blocks.pose.data());
      problem.Hold(s->blocks.betas);
      RunStage(&problem, options_.rigid_iterations, &s->result);
    }
  }

  // 2. Pose and shape on keypoints.
  void SolveKeypoints(FitState* s) const {
    if (options_.keypoint_iterations > 0) {
      StageProblem problem(&s->blocks);
      AddPoseAndShapeTerms(&problem, s);
      RunStage(&problem, options_.keypoint_iterations, &s->result);
    }
  }

  // 3. The views whose masks the silhouette rounds fit: each one's distance transform
  // (in a window around the mask and the hand after the keypoint stages) and outline
  // samples. Views without mask pixels or with the hand out of view are left out.
  SilhouetteEvidence BuildSilhouetteViews(const FitState& s) const {
    const HandFitInput& input = s.input;
    SilhouetteEvidence sil;
    for (int v = 0; v < evaluator_.num_vertices();
         v += options_.silhouette_vertex_stride) {
      sil.vertex_ids.push_back(v);
    }
    if (!s.use_sil) return sil;
    Points3d keypoint_stage_vertices(evaluator_.num_vertices(), 3);
    evaluator_.AllVertices(s.blocks.orient, s.blocks.pose.data(), s.blocks.betas,
                           s.blocks.transl, keypoint_stage_vertices.data());
    for (size_t v = 0; v < input.masks.size(); ++v) {
      if (input.masks[v].size() == 0) continue;
      SilhouetteView view;
      view.camera = input.views[v].camera;
      if (input.masks[v].rows() != view.camera.camera.height() ||
          input.masks[v].cols() != view.camera.camera.width()) {
        throw InputError("HandFitInput", "masks[" + std::to_string(v) + "]",
                         "the camera's image size",
                         std::to_string(input.masks[v].cols()) + "x" +
                             std::to_string(input.masks[v].rows()));
      }
      const MaskImage* occluder = Occluder(input, v);
      const PixelWindow window =
          HandWindow(input.masks[v], view.camera, keypoint_stage_vertices,
                     options_.silhouette_window_margin_px);
      if (window.empty()) continue;  // no mask pixels, hand out of view
      view.distance_to_mask = DistanceToMaskInWindow(input.masks[v], window, occluder);
      view.distance_origin = Eigen::Vector2i(window.x0, window.y0);
      if (!std::isfinite(view.distance_to_mask(0, 0))) continue;  // empty mask
      view.one_sided = occluder == nullptr && input.unknown_occluders;
      view.cap_px = options_.unknown_occluder_cap_px;
      sil.outlines.push_back(SampleMaskOutline(input.masks[v],
                                               options_.silhouette_outline_samples,
                                               occluder, options_.occluder_reach_px));
      sil.views.push_back(std::move(view));
      sil.input_view.push_back(v);
    }
    return sil;
  }

  // Matches each view's outline samples to the hand of `b`, and takes out the view's
  // mask margin (HandFitOptions::mask_margin_max_px), noted in `view_mask_margin_px`.
  void RematchOutlines(const Blocks& b, SilhouetteEvidence* sil,
                       std::vector<double>* view_mask_margin_px) const {
    // Outline samples are matched only to contour-generator vertices (normal nearly
    // perpendicular to the viewing ray): matching interior vertices would pull them
    // outwards and inflate the hand.
    const std::vector<int>& vertex_ids = sil->vertex_ids;
    Points3d all(evaluator_.num_vertices(), 3);
    evaluator_.AllVertices(b.orient, b.pose.data(), b.betas, b.transl, all.data());
    const Points3d normals = ComputeVertexNormals(all, model_.faces);
    for (size_t v = 0; v < sil->views.size(); ++v) {
      SilhouetteView& view = sil->views[v];
      const MaskOutline& outline = sil->outlines[v];
      const Eigen::Vector3d centre = view.camera.CenterInWorld();
      std::vector<Eigen::Vector2d> uv(vertex_ids.size());
      std::vector<char> valid(vertex_ids.size());
      for (size_t i = 0; i < vertex_ids.size(); ++i) {
        const Eigen::Vector3d x = all.row(vertex_ids[i]).transpose();
        const Eigen::Vector3d n = normals.row(vertex_ids[i]).transpose();
        const double along = std::abs(n.dot((x - centre).normalized()));
        valid[i] = n.squaredNorm() > 0.5 && along < options_.silhouette_contour_cosine &&
                   view.camera.ProjectWorld(x, &uv[i]);
      }
      view.outline_px = outline.points;
      view.outline_normal = outline.normals;
      view.outline_vertex = MatchOutlineToPoints(outline, uv, valid);
      if (options_.mask_margin_max_px > 0 && !view.one_sided) {
        const double margin =
            std::clamp(EstimateMaskMargin(outline, view.outline_vertex, uv),
                       -options_.mask_margin_max_px, options_.mask_margin_max_px);
        view.outline_px = ShiftedOutline(outline, margin);
        view.inside_px = 0.5 + std::max(0.0, -margin);
        (*view_mask_margin_px)[sil->input_view[v]] = margin;
      }
    }
  }

  // 3. One silhouette round: outlines re-matched to the current fit, then the keypoint
  // stage's problem with the silhouette term added.
  void SolveSilhouetteRound(SilhouetteEvidence* sil, FitState* s) const {
    RematchOutlines(s->blocks, sil, &s->result.view_mask_margin_px);
    StageProblem problem(&s->blocks);
    AddPoseAndShapeTerms(&problem, s);
    problem.AddFull("silhouette", MultiViewSilhouetteSquareRootCost::Create(
                                      evaluator_, sil->vertex_ids, sil->views,
                                      options_.silhouette_sigma_px));
    RunStage(&problem, options_.silhouette_iterations, &s->result);
  }

  // The stages' report with the final hand and its agreement with the evidence.
  HandFitResult MakeResult(FitState* s,
                           std::chrono::steady_clock::time_point start) const {
    HandFitResult result = std::move(s->result);
    const HandFitStageResult final_stage = Evaluate(s->input, FromBlocks(s->blocks));
    result.params = final_stage.params;
    result.vertices = final_stage.vertices;
    result.keypoints = final_stage.keypoints;
    result.view_rms_px = final_stage.view_rms_px;
    result.view_iou = final_stage.view_iou;
    result.seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
  }

  const HandModel& model_;
  const HandEvaluator& evaluator_;
  const HandAnatomy& anatomy_;
  const HandLimits& limits_;
  const HandFitConfig& config_;
  const HandFitOptions& options_;
};

}  // namespace handlabel::fitting_internal
