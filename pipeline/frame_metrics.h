#pragma once
// Errors of one frame's hand against ground truth (hand/metrics.h, the POEM paper's
// definitions), as scalars that average exactly over frames (every frame has 21
// keypoints and PCK is linear in the frames), so shards merge by averaging:
//   mpjpe_mm     mean keypoint distance
//   pa_mpjpe_mm  the same after Procrustes alignment with scale
//   mpvpe_mm     mean vertex distance (only when both meshes have the same vertices)
//   pa_mpvpe_mm  the same after Procrustes alignment
//   auc          area under the keypoint PCK curve, 0..20 mm in 20 steps (POEM's)
// and over consecutive frames (hand/metrics.h ComputeMotionMetrics), averaged over the
// triples of consecutive frames instead:
//   accel_error_mm  mean |acceleration of the keypoints - the truth's|, mm/frame^2
//   jitter_mm       mean |acceleration of the keypoints|, mm/frame^2

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "pipeline/label_stages.h"

namespace handlabel {

std::map<std::string, double> HandErrors(const Points3d& keypoints,
                                         const Points3d& vertices,
                                         const FrameGroundTruth& truth);

// The name the truth's keypoints go by beside the metric groups' keypoints.
inline constexpr char kTruthKeypoints[] = "truth";

// Keypoints (metres) as the frame log keeps them: x y z per point in millimetres,
// rounded to 1 um (far below any acceleration worth reporting), and back.
std::vector<double> KeypointsToMillimetres(const Points3d& keypoints);
Points3d KeypointsFromMillimetres(const std::vector<double>& millimetres);

// Frame numbers for the motion metrics (hand/metrics.h MotionFrame::number) of frame
// ids in capture order. Neighbours in `ids` are consecutive when they differ only in a
// trailing number that counts up by one ("cam/000041", "cam/000042"); any other
// neighbour (a skipped frame, another recording, ids without a number) is a gap.
std::vector<int64_t> MotionFrameNumbers(const std::vector<std::string>& ids);

}  // namespace handlabel
