#include "fitting/ceres_hand_fitter.h"

#include <string>
#include <vector>

#include "core/errors.h"
#include "core/option_checks.h"
#include "fitting/fit_run.h"
#include "geometry/triangulation.h"

namespace handlabel {

using fitting_internal::FitRun;

void HandFitConfig::Check(const std::string& source) const {
  if (pose_pca_comps != 0 && pose_pca_comps != 12 && pose_pca_comps != 45) {
    throw InputError(source, "pose_pca_comps", "0 (axis-angle), 12 or 45",
                     std::to_string(pose_pca_comps));
  }
}

void HandFitOptions::Check(const std::string& source) const {
  RequireGreater(source, "keypoint_sigma_px", keypoint_sigma_px, 0);
  RequireGreater(source, "keypoint_loss.scale", keypoint_loss.scale, 0);
  RequireGreater(source, "limit_sigma_deg", limit_sigma_deg, 0);
  RequireGreater(source, "pose_prior_sigma_rad", pose_prior_sigma_rad, 0);
  RequireGreater(source, "shape_prior_sigma", shape_prior_sigma, 0);
  RequireGreater(source, "points3d_sigma_m", points3d_sigma_m, 0);
  RequireGreater(source, "temporal_pose_sigma_rad", temporal_pose_sigma_rad, 0);
  RequireGreater(source, "temporal_transl_sigma_m", temporal_transl_sigma_m, 0);
  RequireGreater(source, "silhouette_sigma_px", silhouette_sigma_px, 0);
  RequireAtLeast(source, "silhouette_vertex_stride", silhouette_vertex_stride, 1);
  RequireAtLeast(source, "silhouette_outline_samples", silhouette_outline_samples, 0);
  RequireAtLeast(source, "silhouette_rounds", silhouette_rounds, 0);
  RequireGreater(source, "silhouette_contour_cosine", silhouette_contour_cosine, 0);
  RequireAtLeast(source, "occluder_reach_px", occluder_reach_px, 0);
  RequireAtLeast(source, "silhouette_window_margin_px", silhouette_window_margin_px, 0);
  RequireGreater(source, "unknown_occluder_cap_px", unknown_occluder_cap_px, 0);
  RequireAtLeast(source, "mask_margin_max_px", mask_margin_max_px, 0);
  RequireAtLeast(source, "rigid_skip_below_px", rigid_skip_below_px, 0);
  RequireAtLeast(source, "rigid_iterations", rigid_iterations, 0);
  RequireAtLeast(source, "keypoint_iterations", keypoint_iterations, 0);
  RequireAtLeast(source, "init_iterations", init_iterations, 0);
  RequireAtLeast(source, "silhouette_iterations", silhouette_iterations, 0);
  RequireGreater(source, "function_tolerance", function_tolerance, 0);
  RequireGreater(source, "parameter_tolerance", parameter_tolerance, 0);
  RequireAtLeast(source, "num_threads", num_threads, 1);
  RequireGreater(source, "triangulation_inlier_px", triangulation_inlier_px, 0);
  RequireGreater(source, "fallback_depth_m", fallback_depth_m, 0);
}

namespace {

HandEvaluatorOptions EvaluatorOptionsFor(const HandModel& model, const HandFitConfig& c) {
  if (model.num_betas() < kBetas) {
    throw InputError(model.name, "shapedirs", "at least 10 shape coefficients",
                     std::to_string(model.num_betas()));
  }
  HandEvaluatorOptions o;
  o.num_betas = kBetas;
  o.num_pca_comps = c.pose_pca_comps;
  return o;
}

}  // namespace

CeresHandFitter::CeresHandFitter(const HandModel& model, const HandFitConfig& config,
                                 const HandFitOptions& options)
    : model_(model),
      config_(config),
      options_(options),
      evaluator_(model, (config.Check("HandFitConfig"), options.Check("HandFitOptions"),
                         EvaluatorOptionsFor(model, config))),
      anatomy_(ComputeHandAnatomy(model)),
      limits_(DefaultHandLimits()) {
  if (options.detector_keypoints) {
    options.detector_keypoints->Check("HandFitOptions detector_keypoints",
                                      static_cast<int>(model.num_vertices()));
  }
}

HandParams CeresHandFitter::InitFromKeypoints3d(const Points3d& keypoints,
                                                const Eigen::VectorXd& weights) const {
  const Eigen::Vector3d fallback(0, 0, options_.fallback_depth_m);
  if (evaluator_.pose_dim() == 12) {
    return FitRun<12>(model_, evaluator_, anatomy_, limits_, config_, options_)
        .InitFromKeypoints3d(keypoints, weights, fallback, /*solve=*/true);
  }
  return FitRun<45>(model_, evaluator_, anatomy_, limits_, config_, options_)
      .InitFromKeypoints3d(keypoints, weights, fallback, /*solve=*/true);
}

HandParams CeresHandFitter::InitFromViews(const std::vector<KeypointView>& views) const {
  Rig rig;
  for (size_t v = 0; v < views.size(); ++v) {
    RigCamera camera = views[v].camera;
    camera.name = "view" + std::to_string(v);
    rig.Add(camera);
  }
  RobustTriangulationOptions tri;
  tri.inlier_threshold_px = options_.triangulation_inlier_px;
  Points3d keypoints = Points3d::Zero(kNumHandKeypoints, 3);
  Eigen::VectorXd weights = Eigen::VectorXd::Zero(kNumHandKeypoints);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    std::vector<ViewObservation> observations;
    for (size_t v = 0; v < views.size(); ++v) {
      if (!(views[v].keypoints.confidence[k] > 0.0)) continue;
      observations.push_back({static_cast<int>(v),
                              views[v].keypoints.uv_px.row(k).transpose(),
                              views[v].keypoints.confidence[k]});
    }
    if (observations.size() < 2) continue;
    const RobustTriangulation t = TriangulateRobust(rig, observations, tri);
    if (!t.valid) continue;
    keypoints.row(k) = t.point.transpose();
    weights[k] = 1.0;
  }
  Eigen::Vector3d fallback(0, 0, options_.fallback_depth_m);
  if (!views.empty()) {
    fallback = views[0].camera.cam_from_world.Inverse() * fallback;
  }
  if (evaluator_.pose_dim() == 12) {
    return FitRun<12>(model_, evaluator_, anatomy_, limits_, config_, options_)
        .InitFromKeypoints3d(keypoints, weights, fallback, /*solve=*/false);
  }
  return FitRun<45>(model_, evaluator_, anatomy_, limits_, config_, options_)
      .InitFromKeypoints3d(keypoints, weights, fallback, /*solve=*/false);
}

std::vector<std::string> ViewsWithKeypoints(const std::vector<KeypointView>& views) {
  std::vector<std::string> names;
  for (const KeypointView& view : views) {
    const Keypoints2d& k = view.keypoints;
    for (int i = 0; i < kNumHandKeypoints; ++i) {
      if (k.confidence[i] > 0.0 && k.uv_px.row(i).allFinite()) {
        names.push_back(view.camera.name);
        break;
      }
    }
  }
  return names;
}

void CeresHandFitter::RequireDepthEvidence(const HandFitInput& input) const {
  const bool pulled = (config_.use_points3d && input.targets3d) ||
                      (config_.use_temporal && input.previous);
  if (pulled || !config_.use_keypoints) return;
  const std::vector<std::string> views = ViewsWithKeypoints(input.views);
  if (views.size() >= 2) return;
  throw Error(std::string("2D keypoints in ") +
              (views.empty() ? "no view" : "only 1 view (" + views[0] + ")") +
              ": depth is not determined (a fit from 2D needs keypoints in 2 or more "
              "views, or a network answer or previous frame to pull towards)");
}

HandFitResult CeresHandFitter::Fit(const HandFitInput& input,
                                   const HandParams& init) const {
  RequireDepthEvidence(input);
  if (evaluator_.pose_dim() == 12) {
    return FitRun<12>(model_, evaluator_, anatomy_, limits_, config_, options_)
        .Fit(input, init);
  }
  return FitRun<45>(model_, evaluator_, anatomy_, limits_, config_, options_)
      .Fit(input, init);
}

}  // namespace handlabel
