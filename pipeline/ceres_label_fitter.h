#pragma once
// The labeling job's fitter (label_stages.h LabelFitter) on the Ceres hand fitter of
// fitting/hand_fitter.h:
//   refine (request.init set)  start from the network's 3D keypoints (IK alignment),
//                              keep a 3D pull towards the network's keypoints (and a
//                              subset of its vertices when the meshes match), and fit
//                              to the 2D keypoints (+ silhouettes)
//   fit from 2D only           the paper's multi-view fitting baseline: robust
//                              triangulation of the 2D keypoints, IK alignment, fit
// Silhouettes are used when the request carries them (the network's, evidence.masks:
// network), or when use_masks is set and the capture has mask files.

#include <optional>
#include <string>

#include "core/hand_model.h"
#include "fitting/ceres_hand_fitter.h"
#include "pipeline/label_stages.h"

namespace handlabel {

class CeresLabelFitter : public LabelFitter {
 public:
  // Throws InputError when the config or options do not fit the model.
  // network_mask_sigma_px > 0: silhouettes that come with the request (the network's)
  // are fitted with this residual scale instead of options.silhouette_sigma_px.
  CeresLabelFitter(const HandModel& model, bool use_masks,
                   const HandFitConfig& config = {}, const HandFitOptions& options = {},
                   double network_mask_sigma_px = 0);
  LabelFit Fit(const LabelFitRequest& request) const override;
  std::string Describe() const override;

 private:
  CeresHandFitter fitter_;
  std::optional<CeresHandFitter> network_mask_fitter_;
  int num_vertices_;
  bool use_masks_;
};

}  // namespace handlabel
