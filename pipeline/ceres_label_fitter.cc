#include "pipeline/ceres_label_fitter.h"

#include "core/errors.h"
#include "core/image.h"
#include "pipeline/label_policy.h"

namespace handlabel {
namespace {

// Network vertices pulled in refinement: every n-th (the keypoints carry most of it).
constexpr int kVertexTargetStride = 8;

MaskImage ReadMaskImage(const std::string& path) {
  const ImageU8 image = ReadPng(path);
  MaskImage mask(image.height, image.width);
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) mask(y, x) = image.at(x, y, 0) > 127 ? 255 : 0;
  }
  return mask;
}

}  // namespace

CeresLabelFitter::CeresLabelFitter(const HandModel& model, bool use_masks,
                                   const HandFitConfig& config,
                                   const HandFitOptions& options,
                                   double network_mask_sigma_px)
    : fitter_(model, config, options),
      num_vertices_(model.num_vertices()),
      use_masks_(use_masks) {
  if (network_mask_sigma_px > 0) {
    HandFitOptions coarse = options;
    coarse.silhouette_sigma_px = network_mask_sigma_px;
    network_mask_fitter_.emplace(model, config, coarse);
  }
}

std::string CeresLabelFitter::Describe() const {
  return std::string("Ceres hand fitter (keypoints") +
         (use_masks_ ? " + silhouettes" : "") + ")";
}

LabelFit CeresLabelFitter::Fit(const LabelFitRequest& request) const {
  const FrameInput& frame = *request.frame;
  HandFitInput input;
  for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
    if (!request.keypoints_2d[v]) continue;
    input.views.push_back({frame.rig[v], *request.keypoints_2d[v]});
  }
  // Masks follow the order of input.views.
  std::string silhouettes = "none";
  if (!request.masks.empty()) {
    silhouettes = "network";
    HL_CHECK(request.masks.size() == request.keypoints_2d.size(), "one mask per view");
    for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
      if (request.keypoints_2d[v]) input.masks.push_back(request.masks[v]);
    }
  } else if (use_masks_ && !frame.mask_paths.empty()) {
    silhouettes = "files";
    for (size_t v = 0; v < request.keypoints_2d.size(); ++v) {
      if (!request.keypoints_2d[v]) continue;
      input.masks.push_back(
          frame.mask_paths[v].empty() ? MaskImage() : ReadMaskImage(frame.mask_paths[v]));
    }
  }
  const CeresHandFitter& fitter =
      !request.masks.empty() && network_mask_fitter_ ? *network_mask_fitter_ : fitter_;
  HandParams init;
  if (request.init) {
    const MeshPrediction& net = *request.init;
    Points3dTargets targets;
    targets.keypoints = net.keypoints;
    targets.keypoint_weights = Eigen::VectorXd::Ones(kNumHandKeypoints);
    if (net.vertices.rows() == num_vertices_) {
      for (int v = 0; v < num_vertices_; v += kVertexTargetStride) {
        targets.vertex_ids.push_back(v);
      }
      targets.vertices.resize(targets.vertex_ids.size(), 3);
      for (size_t i = 0; i < targets.vertex_ids.size(); ++i) {
        targets.vertices.row(i) = net.vertices.row(targets.vertex_ids[i]);
      }
    }
    input.targets3d = targets;
    init = fitter.InitFromKeypoints3d(net.keypoints, targets.keypoint_weights);
  } else {
    init = fitter.InitFromViews(input.views);
  }
  const HandFitResult fit = fitter.Fit(input, init);

  LabelFit out;
  out.params = fit.params;
  out.mesh.vertices = fit.vertices;
  out.mesh.keypoints = fit.keypoints;
  out.mesh.joints = NativeJointsFromKeypoints(fit.keypoints);
  // Only deterministic fields: labels must not change between identical runs.
  out.report = {{"init", request.init ? "network" : "triangulated_views"},
                {"iterations", fit.iterations},
                {"converged", fit.converged},
                {"message", fit.message},
                {"term_costs", fit.term_costs},
                {"view_rms_px", fit.view_rms_px},
                {"view_iou", fit.view_iou},
                {"silhouettes", silhouettes}};
  if (silhouettes != "none") {
    out.report["silhouette_sigma_px"] = fitter.options().silhouette_sigma_px;
  }
  return out;
}

}  // namespace handlabel
