#include "fitting/silhouette_outline.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace handlabel {
namespace {
constexpr int kNormalReach = 3;

bool NearOccluder(const MaskImage& occluder, int x, int y, int reach) {
  const int h = static_cast<int>(occluder.rows()), w = static_cast<int>(occluder.cols());
  for (int dy = -reach; dy <= reach; ++dy) {
    for (int dx = -reach; dx <= reach; ++dx) {
      const int u = x + dx, v = y + dy;
      if (u >= 0 && v >= 0 && u < w && v < h && occluder(v, u) != 0) return true;
    }
  }
  return false;
}

}  // namespace

MaskOutline SampleMaskOutline(const MaskImage& mask, int max_samples,
                              const MaskImage* occluder, int occluder_reach_px) {
  const int h = static_cast<int>(mask.rows()), w = static_cast<int>(mask.cols());
  std::vector<Eigen::Vector2i> boundary;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      if (mask(y, x) == 0) continue;
      if (mask(y - 1, x) == 0 || mask(y + 1, x) == 0 || mask(y, x - 1) == 0 ||
          mask(y, x + 1) == 0) {
        if (occluder != nullptr && NearOccluder(*occluder, x, y, occluder_reach_px))
          continue;
        boundary.emplace_back(x, y);
      }
    }
  }
  MaskOutline outline;
  if (boundary.empty() || max_samples <= 0) return outline;
  const double step = std::max(1.0, double(boundary.size()) / max_samples);
  for (double i = 0; i < boundary.size(); i += step) {
    const Eigen::Vector2i& b = boundary[static_cast<size_t>(i)];
    // Outward normal: from the centroid of the mask pixels within +-kNormalReach
    // towards the pixel. Averaging over the window removes the staircase of the pixel
    // grid (one-pixel differences give errors of ~20 degrees).
    Eigen::Vector2d g = Eigen::Vector2d::Zero();
    for (int dy = -kNormalReach; dy <= kNormalReach; ++dy) {
      for (int dx = -kNormalReach; dx <= kNormalReach; ++dx) {
        const int x = b.x() + dx, y = b.y() + dy;
        if (x < 0 || y < 0 || x >= w || y >= h || mask(y, x) == 0) continue;
        g -= Eigen::Vector2d(dx, dy);
      }
    }
    if (g.norm() < 1e-9) continue;
    g.normalize();
    outline.points.push_back(b.cast<double>() + 0.5 * g);
    outline.normals.push_back(g);
  }
  return outline;
}

std::vector<int> MatchOutlineToPoints(const MaskOutline& outline,
                                      const std::vector<Eigen::Vector2d>& projected,
                                      const std::vector<char>& valid) {
  std::vector<int> match(outline.points.size(), -1);
  for (size_t s = 0; s < outline.points.size(); ++s) {
    double best = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < projected.size(); ++i) {
      if (!valid[i]) continue;
      const double d = (projected[i] - outline.points[s]).squaredNorm();
      if (d < best) {
        best = d;
        match[s] = static_cast<int>(i);
      }
    }
  }
  return match;
}

double EstimateMaskMargin(const MaskOutline& outline, const std::vector<int>& matched,
                          const std::vector<Eigen::Vector2d>& projected) {
  std::vector<double> gaps;
  for (size_t s = 0; s < outline.points.size() && s < matched.size(); ++s) {
    if (matched[s] < 0) continue;
    gaps.push_back(outline.normals[s].dot(outline.points[s] - projected[matched[s]]));
  }
  if (gaps.empty()) return 0.0;
  std::nth_element(gaps.begin(), gaps.begin() + gaps.size() / 2, gaps.end());
  return gaps[gaps.size() / 2];
}

std::vector<Eigen::Vector2d> ShiftedOutline(const MaskOutline& outline,
                                            double margin_px) {
  std::vector<Eigen::Vector2d> out(outline.points.size());
  for (size_t s = 0; s < out.size(); ++s)
    out[s] = outline.points[s] - margin_px * outline.normals[s];
  return out;
}

}  // namespace handlabel
