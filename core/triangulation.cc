#include "core/triangulation.h"

#include <Eigen/SVD>
#include <algorithm>
#include <limits>
#include <random>

#include "core/errors.h"

namespace handlabel {

void RobustTriangulationOptions::Check() const {
  const std::string src = "RobustTriangulationOptions";
  if (!(inlier_threshold_px > 0)) {
    throw InputError(src, "inlier_threshold_px", "> 0",
                     std::to_string(inlier_threshold_px));
  }
  if (min_inliers < 2)
    throw InputError(src, "min_inliers", ">= 2", std::to_string(min_inliers));
  if (max_pairs < 1)
    throw InputError(src, "max_pairs", ">= 1", std::to_string(max_pairs));
}

std::optional<Eigen::Vector3d> TriangulateWeighted(
    const Rig& rig, const std::vector<ViewObservation>& observations) {
  Eigen::Matrix<double, Eigen::Dynamic, 4> a(2 * observations.size(), 4);
  int rows = 0;
  for (const ViewObservation& obs : observations) {
    HL_CHECK(obs.camera >= 0 && obs.camera < static_cast<int>(rig.size()),
             "observation camera index");
    if (!(obs.confidence > 0)) continue;
    const RigCamera& cam = rig[obs.camera];
    const Eigen::Vector2d xy = cam.camera.NormalizedFromImage(obs.uv_px);
    const Matrix3x4d p = cam.cam_from_world.ToMatrix();
    a.row(rows++) = obs.confidence * (xy.x() * p.row(2) - p.row(0));
    a.row(rows++) = obs.confidence * (xy.y() * p.row(2) - p.row(1));
  }
  if (rows < 4) return std::nullopt;
  Eigen::JacobiSVD<Eigen::MatrixXd> svd(a.topRows(rows), Eigen::ComputeFullV);
  const Eigen::Vector4d h = svd.matrixV().col(3);
  if (std::abs(h[3]) < 1e-12) return std::nullopt;
  const Eigen::Vector3d point = h.head<3>() / h[3];
  for (const ViewObservation& obs : observations) {
    if (obs.confidence > 0 && (rig[obs.camera].cam_from_world * point).z() <= 0) {
      return std::nullopt;
    }
  }
  return point;
}

double ReprojectionErrorPx(const Rig& rig, const ViewObservation& observation,
                           const Eigen::Vector3d& point_in_world) {
  Eigen::Vector2d uv;
  if (!rig[observation.camera].ProjectWorld(point_in_world, &uv)) {
    return std::numeric_limits<double>::infinity();
  }
  return (uv - observation.uv_px).norm();
}

RobustTriangulation TriangulateRobust(const Rig& rig,
                                      const std::vector<ViewObservation>& observations,
                                      const RobustTriangulationOptions& options) {
  options.Check();
  std::vector<int> usable;
  for (size_t i = 0; i < observations.size(); ++i) {
    if (observations[i].confidence > 0) usable.push_back(static_cast<int>(i));
  }
  RobustTriangulation best;
  if (static_cast<int>(usable.size()) < options.min_inliers) return best;

  std::vector<std::pair<int, int>> pairs;
  for (size_t i = 0; i < usable.size(); ++i) {
    for (size_t j = i + 1; j < usable.size(); ++j)
      pairs.emplace_back(usable[i], usable[j]);
  }
  if (static_cast<int>(pairs.size()) > options.max_pairs) {
    std::mt19937_64 rng(options.seed);
    std::shuffle(pairs.begin(), pairs.end(), rng);
    pairs.resize(options.max_pairs);
  }

  double best_score = -1;
  double best_error = std::numeric_limits<double>::infinity();
  for (const auto& [i, j] : pairs) {
    const auto hypothesis = TriangulateWeighted(rig, {observations[i], observations[j]});
    if (!hypothesis) continue;
    double score = 0;
    double error_sum = 0;
    std::vector<int> inliers;
    for (int k : usable) {
      const double e = ReprojectionErrorPx(rig, observations[k], *hypothesis);
      if (e < options.inlier_threshold_px) {
        inliers.push_back(k);
        score += observations[k].confidence;
        error_sum += e;
      }
    }
    if (score > best_score || (score == best_score && error_sum < best_error)) {
      best_score = score;
      best_error = error_sum;
      best.inliers = std::move(inliers);
      best.point = *hypothesis;
    }
  }
  if (static_cast<int>(best.inliers.size()) < options.min_inliers) {
    best.valid = false;
    return best;
  }
  std::vector<ViewObservation> inlier_obs;
  for (int k : best.inliers) inlier_obs.push_back(observations[k]);
  if (const auto refined = TriangulateWeighted(rig, inlier_obs)) best.point = *refined;
  best.valid = true;
  return best;
}

}  // namespace handlabel
