#include "geometry/triangulation.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <limits>
#include <random>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void RobustTriangulationOptions::Check(const std::string& source) const {
  RequireGreater(source, "inlier_threshold_px", inlier_threshold_px, 0);
  RequireAtLeast(source, "min_inliers", min_inliers, 2);
  RequireAtLeast(source, "max_pairs", max_pairs, 1);
}

namespace {

// An observation with its undistorted normalised coordinates and its camera's projection
// matrix worked out once: RANSAC reuses each observation in many hypotheses.
struct PreparedObservation {
  Eigen::Vector2d xy;
  Matrix3x4d cam_from_world;
  double confidence = 0;
};

PreparedObservation Prepare(const Rig& rig, const ViewObservation& obs) {
  HL_CHECK(obs.camera >= 0 && obs.camera < static_cast<int>(rig.size()),
           "observation camera index");
  const RigCamera& cam = rig[obs.camera];
  return {cam.camera.NormalizedFromImage(obs.uv_px), cam.cam_from_world.ToMatrix(),
          obs.confidence};
}

// DLT through the 4x4 normal matrix A^T A: its eigenvector of the smallest eigenvalue is
// A's last right singular vector, at a fixed size whatever the number of views.
std::optional<Eigen::Vector3d> TriangulatePrepared(
    const std::vector<const PreparedObservation*>& observations) {
  Eigen::Matrix4d normal = Eigen::Matrix4d::Zero();
  int used = 0;
  for (const PreparedObservation* obs : observations) {
    if (!(obs->confidence > 0)) continue;
    const Matrix3x4d& p = obs->cam_from_world;
    const Eigen::RowVector4d rx = obs->confidence * (obs->xy.x() * p.row(2) - p.row(0));
    const Eigen::RowVector4d ry = obs->confidence * (obs->xy.y() * p.row(2) - p.row(1));
    normal.noalias() += rx.transpose() * rx + ry.transpose() * ry;
    ++used;
  }
  if (used < 2) return std::nullopt;
  // The normal matrix is symmetric: its eigen-decomposition (eigenvalues ascending)
  // gives the same vector as an SVD, several times faster.
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eigen(normal);
  const Eigen::Vector4d h = eigen.eigenvectors().col(0);
  if (std::abs(h[3]) < 1e-12) return std::nullopt;
  const Eigen::Vector3d point = h.head<3>() / h[3];
  for (const PreparedObservation* obs : observations) {
    if (obs->confidence > 0 && obs->cam_from_world.row(2).dot(point.homogeneous()) <= 0) {
      return std::nullopt;
    }
  }
  return point;
}

}  // namespace

std::optional<Eigen::Vector3d> TriangulateWeighted(
    const Rig& rig, const std::vector<ViewObservation>& observations) {
  std::vector<PreparedObservation> prepared;
  std::vector<const PreparedObservation*> pointers;
  prepared.reserve(observations.size());
  for (const ViewObservation& obs : observations) {
    prepared.push_back(Prepare(rig, obs));
    pointers.push_back(&prepared.back());
  }
  return TriangulatePrepared(pointers);
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
  options.Check("RobustTriangulationOptions");
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

  std::vector<PreparedObservation> prepared(observations.size());
  for (int k : usable) prepared[k] = Prepare(rig, observations[k]);

  double best_score = -1;
  double best_error = std::numeric_limits<double>::infinity();
  for (const auto& [i, j] : pairs) {
    // Once every observation is an inlier no hypothesis can change the inlier set,
    // and the answer is the DLT over that set: the clean case needs one pair.
    if (best.inliers.size() == usable.size()) break;
    const auto hypothesis = TriangulatePrepared({&prepared[i], &prepared[j]});
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
  std::vector<const PreparedObservation*> inlier_obs;
  for (int k : best.inliers) inlier_obs.push_back(&prepared[k]);
  if (const auto refined = TriangulatePrepared(inlier_obs)) best.point = *refined;
  best.valid = true;
  return best;
}

}  // namespace handlabel
