#include "pipeline/frame_metrics.h"

#include <cctype>
#include <cmath>

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

namespace {

// `id` split into what comes before its trailing digits and their value; false when it
// ends in no digit or in more than 18 (beyond int64).
bool SplitTrailingNumber(const std::string& id, std::string* prefix, int64_t* number) {
  size_t start = id.size();
  while (start > 0 && std::isdigit(static_cast<unsigned char>(id[start - 1]))) --start;
  const size_t digits = id.size() - start;
  if (digits == 0 || digits > 18) return false;
  *prefix = id.substr(0, start);
  *number = std::stoll(id.substr(start));
  return true;
}

bool ConsecutiveFrameIds(const std::string& before, const std::string& after) {
  std::string prefix_before, prefix_after;
  int64_t number_before = 0, number_after = 0;
  return SplitTrailingNumber(before, &prefix_before, &number_before) &&
         SplitTrailingNumber(after, &prefix_after, &number_after) &&
         prefix_before == prefix_after && number_after == number_before + 1;
}

}  // namespace

std::vector<double> KeypointsToMillimetres(const Points3d& keypoints) {
  std::vector<double> mm;
  for (Eigen::Index i = 0; i < keypoints.rows(); ++i) {
    for (int a = 0; a < 3; ++a) mm.push_back(std::round(keypoints(i, a) * 1e6) / 1e3);
  }
  return mm;
}

Points3d KeypointsFromMillimetres(const std::vector<double>& millimetres) {
  HL_CHECK(millimetres.size() % 3 == 0, "x y z per keypoint");
  Points3d keypoints(millimetres.size() / 3, 3);
  for (size_t i = 0; i < millimetres.size(); ++i) {
    keypoints(i / 3, i % 3) = millimetres[i] / 1e3;
  }
  return keypoints;
}

std::vector<int64_t> MotionFrameNumbers(const std::vector<std::string>& ids) {
  std::vector<int64_t> numbers(ids.size());
  for (size_t i = 1; i < ids.size(); ++i) {
    numbers[i] = numbers[i - 1] + (ConsecutiveFrameIds(ids[i - 1], ids[i]) ? 1 : 2);
  }
  return numbers;
}

}  // namespace handlabel
