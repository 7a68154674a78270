#pragma once
// The labeling job's fitting stage: the LabelFitter interface (label_stages.h)
// implemented on the Ceres hand fitter of fitting/ceres_hand_fitter.h. Names follow the
// other stages (NativeFrameSource, NetworkStage): CeresHandFitter solves the
// problem; CeresLabelFitter turns a frame and its evidence into that problem.
//   refine (request.init set)  start from the network's 3D keypoints (IK alignment),
//                              keep a 3D pull towards the network's keypoints (and a
//                              subset of its vertices when the meshes match), and fit
//                              to the 2D keypoints (+ silhouettes)
//   fit from 2D only           the paper's multi-view fitting baseline (`handlabel fit`
//                              and a job without network): start per `init` (job
//                              field fit.init; by default robust triangulation of the
//                              2D keypoints + IK alignment), then fit; a frame
//                              with 2D keypoints in fewer than 2 views fails
//                              (depth is not determined: CeresHandFitter::Fit)
// Silhouettes are used when the request carries them (the network's, evidence.masks:
// network), or when use_masks is set and the frame has mask files (read with the one
// mask rule of image/mask_image.h). A fit with silhouettes is checked against the
// keypoints-only fit it started from (CheckSilhouetteFit, pipeline/quality_checks.h);
// when the check fails, the keypoints-only fit is the label. The report says which
// (`used`: silhouettes | keypoints_only, `used_why`, `silhouette_check`).

#include <optional>
#include <string>
#include <vector>

#include "fitting/ceres_hand_fitter.h"
#include "hand/hand_model.h"
#include "pipeline/label_stages.h"
#include "pipeline/quality_checks.h"

namespace handlabel {

struct CeresLabelFitterOptions {
  // Fit to the frame's mask files (evidence.masks: files).
  bool use_masks = false;
  // With mask files: the frame's object masks are occluders (evidence.object_masks).
  bool use_object_masks = true;
  // Without object masks (use_object_masks false): true = one-sided silhouettes
  // (HandFitInput::unknown_occluders); false = the two-sided term, guarded by the
  // silhouette check (measured safer: docs/fitting.md "Occlusion").
  bool one_sided_without_object_masks = false;
  // Keep a silhouette fit only when it passes these; else the keypoints-only fit.
  bool check_silhouettes = true;
  SilhouetteCheckThresholds silhouette_check;
  HandFitConfig config;
  HandFitOptions fit;
  // > 0: silhouettes that come with the request (the network's) are fitted with this
  // residual scale instead of fit.silhouette_sigma_px.
  double network_mask_sigma_px = 0;
  // Start of a fit from 2D evidence alone: triangulate | gt | previous | a folder of
  // per-frame parameter files (job field fit.init, pipeline/job_config.h).
  std::string init = "triangulate";
  // Refining a network answer against file (detector) 2D: its 21 keypoints pull with
  // this sigma (metres; job field refine.network_sigma_mm) and its vertices not at all.
  // The network's error is centimetres where it has not been adapted to the rig; at
  // fit.points3d_sigma_m (2 mm) its pull outvotes the detector's views and the refined
  // answer stays where the network put it. Without file 2D the network's own answer
  // and 2D are all there is, and it keeps the tight pull.
  double network_sigma_m = 0.02;
  // ... and when the network's start reprojects further than this from the file views
  // (worst view RMS, px; refine.restart_px), the fit also runs from the triangulated
  // views and keeps whichever ends with the lower keypoint cost. 0: always both.
  double restart_px = 40;
};

class CeresLabelFitter : public LabelFitter {
 public:
  // Throws InputError when the config or options do not fit the model.
  CeresLabelFitter(const HandModel& model, const CeresLabelFitterOptions& options = {});
  LabelFit Fit(const LabelFitRequest& request) const override;
  std::string Describe() const override;

 private:
  // The views with 2D evidence and their silhouettes; `silhouettes` says where the
  // masks came from (none | network | files).
  HandFitInput Evidence(const LabelFitRequest& request, std::string* silhouettes) const;
  // The start of the solve (and the 3D targets or temporal pull it implies); `start`
  // names it for the report.
  HandParams Start(const LabelFitRequest& request, const CeresHandFitter& fitter,
                   HandFitInput* input, std::string* start) const;
  // Refinement against file 2D: from the network's answer, loosely pulled, and from
  // the triangulated views too when that answer is far from the file views; the fit
  // with the lower keypoint cost wins. `start` names the winner's start; `times` gets
  // the stage times of both fits (LabelFit::stage_seconds).
  HandFitResult RefineAgainstFiles(const LabelFitRequest& request,
                                   const CeresHandFitter& fitter,
                                   const HandFitInput& input, std::string* start,
                                   StageSeconds* times) const;

  // With silhouette rounds run: the check of the silhouette fit; when it fails and
  // check_silhouettes is set, `fit` becomes its keypoints-only result.
  std::optional<QualityReport> CheckSilhouettes(HandFitResult* fit) const;

  CeresHandFitter fitter_;
  std::optional<CeresHandFitter> network_mask_fitter_;
  int num_vertices_;
  CeresLabelFitterOptions options_;
};

}  // namespace handlabel
