#include "fitting/silhouette_outline.h"

#include <cmath>
#include <limits>

namespace handlabel {
namespace {
constexpr int kNormalReach = 3;
}  // namespace

MaskOutline SampleMaskOutline(const MaskImage& mask, int max_samples) {
  const int h = static_cast<int>(mask.rows()), w = static_cast<int>(mask.cols());
  std::vector<Eigen::Vector2i> boundary;
  for (int y = 1; y + 1 < h; ++y) {
    for (int x = 1; x + 1 < w; ++x) {
      if (mask(y, x) == 0) continue;
      if (mask(y - 1, x) == 0 || mask(y + 1, x) == 0 || mask(y, x - 1) == 0 ||
          mask(y, x + 1) == 0) {
        boundary.emplace_back(x, y);
      }
    }
  }
  MaskOutline outline;
  if (boundary.empty() || max_samples <= 0) return outline;
  const DistanceImage outside = DistanceToMask(mask);
  const DistanceImage inside = DistanceToOutside(mask);
  auto signed_distance = [&](int x, int y) { return outside(y, x) - inside(y, x); };
  const double step = std::max(1.0, double(boundary.size()) / max_samples);
  for (double i = 0; i < boundary.size(); i += step) {
    const Eigen::Vector2i& b = boundary[static_cast<size_t>(i)];
    Eigen::Vector2d g(
        signed_distance(b.x() + 1, b.y()) - signed_distance(b.x() - 1, b.y()),
        signed_distance(b.x(), b.y() + 1) - signed_distance(b.x(), b.y() - 1));
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

}  // namespace handlabel
