#pragma once
// Errors of one frame's hand against ground truth, as scalars that average exactly
// over frames (every frame has 21 keypoints), so shards can be merged by averaging:
//   mpjpe_mm     mean keypoint distance
//   pa_mpjpe_mm  the same after the best similarity transform (Procrustes: rotation,
//                translation, scale) of the keypoints onto the ground truth
//   mpvpe_mm     mean vertex distance (only when both meshes have the same vertices)
//   auc          area under the PCK curve for thresholds 0..50 mm, normalised to [0, 1]
//                (per keypoint exactly max(0, 1 - error / 50 mm))

#include <map>
#include <string>

#include "pipeline/label_stages.h"

namespace handlabel {

constexpr double kAucMaxThresholdMm = 50.0;

std::map<std::string, double> HandErrors(const Points3d& keypoints,
                                         const Points3d& vertices,
                                         const HandGroundTruth& truth);

}  // namespace handlabel
