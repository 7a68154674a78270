#pragma once
// Triangulating one 3D point from its pixel observations in several rig views.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "geometry/rig.h"

namespace handlabel {

struct ViewObservation {
  int camera = 0;           // index into the rig
  Eigen::Vector2d uv_px;    // distorted pixel, as detected
  double confidence = 1.0;  // >= 0; 0 ignores the view
};

// Linear triangulation (DLT) in undistorted normalised coordinates; each view's two
// equations are scaled by its confidence. Returns nothing if fewer than two views have
// positive confidence or the solution lies at infinity or behind a used camera.
std::optional<Eigen::Vector3d> TriangulateWeighted(
    const Rig& rig, const std::vector<ViewObservation>& observations);

struct RobustTriangulationOptions {
  // A view is an inlier if its reprojection error is below this (pixels).
  double inlier_threshold_px = 10.0;
  // Fewest inlier views for a valid point.
  int min_inliers = 2;
  // Pairs of views tried as minimal samples. If the number of pairs is at most this,
  // every pair is tried (deterministic); otherwise pairs are drawn with `seed`.
  int max_pairs = 100;
  uint64_t seed = 0;
  // Throws InputError naming the field if a value is out of range.
  void Check(const std::string& source) const;
};

struct RobustTriangulation {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  std::vector<int> inliers;  // indices into the observations
  bool valid = false;
};

// RANSAC over views: hypotheses from pairs of views, scored by the summed confidence
// of inliers (ties: lower summed error), then refined by weighted DLT on the inliers.
RobustTriangulation TriangulateRobust(const Rig& rig,
                                      const std::vector<ViewObservation>& observations,
                                      const RobustTriangulationOptions& options = {});

// Pixel distance between an observation and the projection of a world point
// (infinity if behind the camera).
double ReprojectionErrorPx(const Rig& rig, const ViewObservation& observation,
                           const Eigen::Vector3d& point_in_world);

}  // namespace handlabel
