#pragma once
// Errors of one frame's hand against ground truth (hand/metrics.h, the POEM paper's
// definitions), as scalars that average exactly over frames (every frame has 21
// keypoints and PCK is linear in the frames), so shards merge by averaging:
//   mpjpe_mm     mean keypoint distance
//   pa_mpjpe_mm  the same after Procrustes alignment with scale
//   mpvpe_mm     mean vertex distance (only when both meshes have the same vertices)
//   pa_mpvpe_mm  the same after Procrustes alignment
//   auc          area under the keypoint PCK curve, 0..20 mm in 20 steps (POEM's)

#include <map>
#include <string>

#include "pipeline/label_stages.h"

namespace handlabel {

std::map<std::string, double> HandErrors(const Points3d& keypoints,
                                         const Points3d& vertices,
                                         const FrameGroundTruth& truth);

}  // namespace handlabel
