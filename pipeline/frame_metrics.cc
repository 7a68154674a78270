#include "pipeline/frame_metrics.h"

#include <Eigen/Geometry>

#include "core/errors.h"

namespace handlabel {

std::map<std::string, double> HandErrors(const Points3d& keypoints,
                                         const Points3d& vertices,
                                         const HandGroundTruth& truth) {
  HL_CHECK(keypoints.rows() == kNumHandKeypoints &&
               truth.keypoints.rows() == kNumHandKeypoints,
           "21 keypoints");
  std::map<std::string, double> errors;
  const Eigen::VectorXd distance_mm =
      1000.0 * (keypoints - truth.keypoints).rowwise().norm();
  errors["mpjpe_mm"] = distance_mm.mean();
  errors["auc"] =
      (1.0 - distance_mm.array() / kAucMaxThresholdMm).max(0.0).matrix().mean();

  const Eigen::Matrix3Xd source = keypoints.transpose();
  const Eigen::Matrix3Xd target = truth.keypoints.transpose();
  const Eigen::Matrix4d target_from_source = Eigen::umeyama(source, target, true);
  const Eigen::Matrix3Xd aligned =
      (target_from_source.topLeftCorner<3, 3>() * source).colwise() +
      target_from_source.topRightCorner<3, 1>();
  errors["pa_mpjpe_mm"] = 1000.0 * (aligned - target).colwise().norm().mean();

  if (truth.vertices.rows() > 0 && truth.vertices.rows() == vertices.rows()) {
    errors["mpvpe_mm"] = 1000.0 * (vertices - truth.vertices).rowwise().norm().mean();
  }
  return errors;
}

}  // namespace handlabel
