#include "pipeline/ceres_label_fitter.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/json_util.h"
#include "hand/hand_params_json.h"
#include "image/mask_image.h"
#include "image/view_image.h"
#include "pipeline/label_policy.h"
#include "pipeline/label_record.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Network vertices pulled in refinement: every n-th (the keypoints carry most of it).
constexpr int kVertexTargetStride = 8;

// A label of a job (label_record.h), or MANO parameters at the top or under "params".
HandParams ParamsFromJson(const json& file, const std::string& source) {
  if (file.value("format", "") == "handlabel-label") {
    const LabelRecord label = LabelFromJson(file, source);
    if (!label.params) throw InputError(source, "mano", "a label with MANO parameters");
    return *label.params;
  }
  const json& j =
      file.contains("params") && file["params"].is_object() ? file["params"] : file;
  for (const char* key : {"global_orient", "hand_pose", "betas", "transl"}) {
    if (!j.contains(key)) {
      throw InputError(source, key,
                       "MANO parameters (global_orient, hand_pose, betas, transl)");
    }
  }
  // Shared reader: also refuses implausible magnitudes (1e300) and NaN.
  return HandParamsFromJson(j, source);
}

HandParams ReadInitFile(const std::string& dir, const std::string& frame) {
  const std::string stem = FrameFileStem(frame, dir);
  for (const std::string& rel :
       {frame + ".json", "frames/" + frame + ".json", "labels/" + stem + ".json"}) {
    const fs::path path = fs::path(dir) / rel;
    if (!fs::exists(path)) continue;
    return ParamsFromJson(ReadJsonFileStrict(path.string()), path.string());
  }
  throw InputError("fit.init " + dir, frame + ".json",
                   "a per-frame parameter file (<frame>.json, frames/ or labels/)");
}

// The network's answer as 3D targets: its keypoints with `keypoint_weight` each and,
// when with_vertices, every kVertexTargetStride-th vertex.
Points3dTargets NetworkTargets(const MeshPrediction& net, int num_vertices,
                               double keypoint_weight, bool with_vertices) {
  Points3dTargets targets;
  targets.keypoints = net.keypoints;
  targets.keypoint_weights =
      Eigen::VectorXd::Constant(kNumHandKeypoints, keypoint_weight);
  if (with_vertices && net.vertices.rows() == num_vertices) {
    for (int v = 0; v < num_vertices; v += kVertexTargetStride) {
      targets.vertex_ids.push_back(v);
    }
    targets.vertices.resize(targets.vertex_ids.size(), 3);
    for (size_t i = 0; i < targets.vertex_ids.size(); ++i) {
      targets.vertices.row(i) = net.vertices.row(targets.vertex_ids[i]);
    }
  }
  return targets;
}

// A mask file (hand or object labels) of one view, read and checked against the camera's
// image size, so that a mismatch names the file and the camera (the fitter knows
// neither).
MaskImage ReadViewMask(const std::string& path, const RigCamera& camera, bool objects) {
  MaskImage mask = objects ? ReadObjectMaskPng(path) : ReadMaskPng(path);
  CheckViewImageSize(path, mask.cols(), mask.rows(), camera);
  return mask;
}

// The worst view's RMS distance (px) between the projected `keypoints` and the view's
// 2D keypoints with confidence > 0; 0 without any.
double WorstViewRmsPx(const std::vector<KeypointView>& views, const Points3d& keypoints) {
  double worst = 0;
  for (const KeypointView& view : views) {
    double sum = 0;
    int count = 0;
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      Eigen::Vector2d uv;
      if (!(view.keypoints.confidence[k] > 0) ||
          !view.camera.ProjectWorld(keypoints.row(k).transpose(), &uv)) {
        continue;
      }
      sum += (uv - view.keypoints.uv_px.row(k).transpose()).squaredNorm();
      ++count;
    }
    if (count > 0) worst = std::max(worst, std::sqrt(sum / count));
  }
  return worst;
}

// What a fit's answer costs against the evidence alone: every term but the pull
// towards the network's answer, so that fits with and without that pull compare.
double EvidenceCost(const HandFitResult& fit) {
  double total = 0;
  for (const auto& [term, cost] : fit.term_costs) {
    if (term != "points3d") total += cost;
  }
  return total;
}

}  // namespace

CeresLabelFitter::CeresLabelFitter(const HandModel& model,
                                   const CeresLabelFitterOptions& options)
    : fitter_(model, options.config, options.fit),
      num_vertices_(model.num_vertices()),
      options_(options) {
  options.silhouette_check.Check("silhouette check");
  if (options.network_mask_sigma_px > 0) {
    HandFitOptions coarse = options.fit;
    coarse.silhouette_sigma_px = options.network_mask_sigma_px;
    network_mask_fitter_.emplace(model, options.config, coarse);
  }
}

std::string CeresLabelFitter::Describe() const {
  return std::string("Ceres hand fitter (keypoints") +
         (options_.use_masks ? " + silhouettes" : "") + ")";
}

HandFitInput CeresLabelFitter::Evidence(const LabelFitRequest& request,
                                        std::string* silhouettes) const {
  const FrameInput& frame = *request.frame;
  HandFitInput input;
  for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
    if (!request.keypoints_2d[v]) continue;
    input.views.push_back({frame.rig[v], *request.keypoints_2d[v]});
  }
  // Masks follow the order of input.views.
  *silhouettes = "none";
  if (!request.masks.empty()) {
    *silhouettes = "network";
    HL_CHECK(request.masks.size() == request.keypoints_2d.size(), "one mask per view");
    for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
      if (request.keypoints_2d[v]) input.masks.push_back(request.masks[v]);
    }
  } else if (options_.use_masks && (!frame.mask_paths.empty() || !frame.masks.empty())) {
    // Masks the reader decoded (frame.masks) or mask files.
    *silhouettes = "files";
    for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
      if (!request.keypoints_2d[v]) continue;
      input.masks.push_back(!frame.masks.empty() ? frame.masks[v]
                            : frame.mask_paths[v].empty()
                                ? MaskImage()
                                : ReadViewMask(frame.mask_paths[v], frame.rig[v], false));
    }
    if (!options_.use_object_masks && options_.one_sided_without_object_masks) {
      *silhouettes = "files+one_sided";
      input.unknown_occluders = true;
    }
    if (options_.use_object_masks &&
        (!frame.object_mask_paths.empty() || !frame.object_masks.empty())) {
      *silhouettes = "files+object_masks";
      for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
        if (!request.keypoints_2d[v]) continue;
        if (!frame.object_masks.empty()) {
          input.occluder_masks.push_back(frame.object_masks[v]);
          continue;
        }
        const std::string& path = frame.object_mask_paths[v];
        input.occluder_masks.push_back(
            path.empty() ? MaskImage() : ReadViewMask(path, frame.rig[v], true));
      }
    }
  }
  return input;
}

HandParams CeresLabelFitter::Start(const LabelFitRequest& request,
                                   const CeresHandFitter& fitter, HandFitInput* input,
                                   std::string* start) const {
  const FrameInput& frame = *request.frame;
  if (request.init) {
    *start = "network";
    input->targets3d = NetworkTargets(*request.init, num_vertices_, 1.0, true);
    return fitter.InitFromKeypoints3d(request.init->keypoints,
                                      input->targets3d->keypoint_weights);
  }
  const std::string& init = options_.init;
  if (init == "gt") {
    if (!frame.ground_truth || !frame.ground_truth->params) {
      throw Error("fit.init is gt, and frame " + frame.id +
                  " has no ground-truth parameters");
    }
    *start = "ground_truth";
    return *frame.ground_truth->params;
  }
  if (init == "previous" && request.previous) {
    *start = "previous_label";
    input->previous = *request.previous;
    return *request.previous;
  }
  if (init != "triangulate" && init != "previous") {
    *start = "file";
    return ReadInitFile(init, frame.id);
  }
  *start = "triangulated_views";
  return fitter.InitFromViews(input->views);
}

HandFitResult CeresLabelFitter::RefineAgainstFiles(const LabelFitRequest& request,
                                                   const CeresHandFitter& fitter,
                                                   const HandFitInput& input,
                                                   std::string* start,
                                                   StageSeconds* times) const {
  const MeshPrediction& net = *request.init;
  // A target at sigma s with weight w pulls as one at sigma s / sqrt(w).
  const double sigma_ratio = fitter.options().points3d_sigma_m / options_.network_sigma_m;
  HandFitInput from_network = input;
  from_network.targets3d =
      NetworkTargets(net, num_vertices_, sigma_ratio * sigma_ratio, false);
  *start = "network";
  HandParams init;
  {
    StageTimer timer(times, "init");
    init = fitter.InitFromKeypoints3d(net.keypoints,
                                      Eigen::VectorXd::Ones(kNumHandKeypoints));
  }
  HandFitResult fit = fitter.Fit(from_network, init);
  AddStageSeconds(fit.stage_seconds, times);
  if (WorstViewRmsPx(input.views, net.keypoints) <= options_.restart_px) return fit;
  // A restart from the views alone needs two of them (CeresHandFitter::Fit): from one,
  // the network's pull is all that places the hand in depth.
  if (ViewsWithKeypoints(input.views).size() < 2) {
    *start = "network (one view: no triangulated restart)";
    return fit;
  }
  HandParams from_views_init;
  {
    StageTimer timer(times, "init");
    from_views_init = fitter.InitFromViews(input.views);
  }
  HandFitResult from_views = fitter.Fit(input, from_views_init);
  AddStageSeconds(from_views.stage_seconds, times);
  if (EvidenceCost(from_views) < EvidenceCost(fit)) {
    *start = "triangulated_views (network start too far)";
    return from_views;
  }
  *start = "network (triangulated restart fitted worse)";
  return fit;
}

std::optional<QualityReport> CeresLabelFitter::CheckSilhouettes(
    HandFitResult* fit) const {
  if (!fit->keypoints_only) return std::nullopt;
  HandFitStageResult& kp = *fit->keypoints_only;
  const HandFitStageResult silhouette_fit{fit->params, fit->vertices, fit->keypoints,
                                          fit->view_rms_px, fit->view_iou};
  QualityReport report =
      CheckSilhouetteFit(silhouette_fit, kp, options_.silhouette_check);
  if (!report.Passed() && options_.check_silhouettes) {
    fit->params = kp.params;
    fit->vertices = std::move(kp.vertices);
    fit->keypoints = std::move(kp.keypoints);
    fit->view_rms_px = std::move(kp.view_rms_px);
    fit->view_iou = std::move(kp.view_iou);
  }
  return report;
}

LabelFit CeresLabelFitter::Fit(const LabelFitRequest& request) const {
  LabelFit out;
  StageSeconds* times = &out.stage_seconds;
  std::string silhouettes, start;
  HandFitInput input;
  {
    StageTimer timer(times, "evidence");
    input = Evidence(request, &silhouettes);
  }
  const CeresHandFitter& fitter =
      !request.masks.empty() && network_mask_fitter_ ? *network_mask_fitter_ : fitter_;
  HandFitResult fit;
  if (request.init && request.file_views > 0) {
    fit = RefineAgainstFiles(request, fitter, input, &start, times);
  } else {
    HandParams init;
    {
      StageTimer timer(times, "init");
      init = Start(request, fitter, &input, &start);
    }
    fit = fitter.Fit(input, init);
    AddStageSeconds(fit.stage_seconds, times);
  }
  std::optional<QualityReport> check;
  {
    StageTimer timer(times, "silhouette_check");
    check = CheckSilhouettes(&fit);
  }

  out.params = fit.params;
  out.mesh.vertices = fit.vertices;
  out.mesh.keypoints = fit.keypoints;
  out.mesh.joints = NativeJointsFromKeypoints(fit.keypoints);
  // Only deterministic fields: labels must not change between identical runs.
  out.report = {{"init", start},
                {"iterations", fit.iterations},
                {"converged", fit.converged},
                {"message", fit.message},
                {"term_costs", fit.term_costs},
                {"view_rms_px", fit.view_rms_px},
                {"view_iou", fit.view_iou},
                {"silhouettes", silhouettes}};
  if (check) {
    nlohmann::json flags = nlohmann::json::array();
    for (const QualityFlag& f : check->flags) flags.push_back(QualityFlagJson(f));
    out.report["silhouette_check"] = flags;
    const bool keep = check->Passed() || !options_.check_silhouettes;
    out.report["used"] = keep ? "silhouettes" : "keypoints_only";
    out.report["used_why"] =
        check->Passed() ? "silhouette check passed"
        : options_.check_silhouettes
            ? "silhouette check failed: " + check->FailedNames()
            : "silhouette check off (failed: " + check->FailedNames() + ")";
  }
  if (silhouettes != "none") {
    out.report["silhouette_sigma_px"] = fitter.options().silhouette_sigma_px;
    out.report["view_mask_margin_px"] = fit.view_mask_margin_px;
  }
  return out;
}

}  // namespace handlabel
