#include "pipeline/frame_metrics.h"

#include "core/errors.h"
#include "hand/metrics.h"

namespace handlabel {

std::map<std::string, double> HandErrors(const Points3d& keypoints,
                                         const Points3d& vertices,
                                         const FrameGroundTruth& truth) {
  HL_CHECK(keypoints.rows() == kNumHandKeypoints &&
               truth.keypoints.rows() == kNumHandKeypoints,
           "21 keypoints");
  std::map<std::string, double> errors;
  errors["mpjpe_mm"] = 1000.0 * MeanPointError(keypoints, truth.keypoints);
  errors["pa_mpjpe_mm"] = 1000.0 * ProcrustesMeanPointError(keypoints, truth.keypoints);
  const Eigen::MatrixXd per_keypoint =
      PointErrors(keypoints, truth.keypoints).transpose();
  errors["auc"] = ComputePck(per_keypoint).auc;
  if (truth.vertices.rows() > 0 && truth.vertices.rows() == vertices.rows()) {
    errors["mpvpe_mm"] = 1000.0 * MeanPointError(vertices, truth.vertices);
    errors["pa_mpvpe_mm"] = 1000.0 * ProcrustesMeanPointError(vertices, truth.vertices);
  }
  return errors;
}

}  // namespace handlabel
