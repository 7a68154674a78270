#include "openhand/skinning.h"

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "core/option_checks.h"
#include "openhand/mesh_decimation.h"

namespace handlabel {
namespace {

double SmoothStep(double t) {
  t = std::clamp(t, 0.0, 1.0);
  return t * t * (3.0 - 2.0 * t);
}

double SegmentDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                       const Eigen::Vector3d& b) {
  const Eigen::Vector3d d = b - a;
  const double t = std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * d)).norm();
}

}  // namespace

void OpenHandSkinningOptions::Check(const std::string& source) const {
  if (!(finger_blend > 0.0) || !(thumb_cmc_blend > 0.0)) {
    throw InputError(source, "finger_blend / thumb_cmc_blend", "positive values");
  }
  RequireAtLeast(source, "smoothing_rounds", smoothing_rounds, 0);
  // Open above, so not RequireInRange.
  if (!(min_weight >= 0.0 && min_weight < 0.1)) {
    throw InputError(source, "min_weight", "[0, 0.1)", OptionValueText(min_weight));
  }
}

std::array<std::array<int, 3>, 5> OpenHandChains() {
  return {{{13, 14, 15}, {1, 2, 3}, {4, 5, 6}, {10, 11, 12}, {7, 8, 9}}};
}

SkinningWeights OpenHandSkinningWeights(const TriangleMesh& mesh,
                                        const OpenHandSkeleton& sk,
                                        const OpenHandSkinningOptions& options) {
  options.Check("skinning options");
  const auto chains = OpenHandChains();
  const int num_vertices = static_cast<int>(mesh.vertices.size());
  SkinningWeights w = SkinningWeights::Zero(num_vertices, kNumHandJoints);
  for (int v = 0; v < num_vertices; ++v) {
    const Eigen::Vector3d& p = mesh.vertices[v];
    // Nearest chain, measured from the bone axes relative to the local radius.
    int chain = 0;
    double best = 1e9;
    for (int c = 0; c < 5; ++c) {
      for (int k = 0; k < 3; ++k) {
        const int j = chains[c][k];
        const Eigen::Vector3d& a = sk.joints[j];
        const Eigen::Vector3d& b = k < 2 ? sk.joints[chains[c][k + 1]] : sk.tips[c];
        const double d = SegmentDistance(p, a, b) / sk.radii[j];
        if (d < best) best = d, chain = c;
      }
    }
    const auto& ids = chains[chain];
    std::array<double, 3> past{};  // fraction of the vertex past each joint's plane
    for (int k = 0; k < 3; ++k) {
      const int j = ids[k];
      const Eigen::Vector3d out =
          ((k < 2 ? sk.joints[ids[k + 1]] : sk.tips[chain]) - sk.joints[j]).normalized();
      Eigen::Vector3d axis = out;
      if (k > 0)
        axis = (out + (sk.joints[j] - sk.joints[ids[k - 1]]).normalized()).normalized();
      const double blend =
          (chain == 0 && k == 0 ? options.thumb_cmc_blend : options.finger_blend) *
          sk.radii[j];
      past[k] = SmoothStep(0.5 + 0.5 * (p - sk.joints[j]).dot(axis) / blend);
      if (k == 0) {
        // Far from the first bone's axis (palm, web) the vertex stays with the wrist.
        const Eigen::Vector3d q = p - sk.joints[j];
        const double radial = (q - q.dot(axis) * axis).norm() / sk.radii[j];
        past[k] *= 1.0 - SmoothStep((radial - 1.3) / 1.0);
      } else {
        past[k] = std::min(past[k], past[k - 1]);
      }
    }
    w(v, 0) = 1.0 - past[0];
    w(v, ids[0]) = past[0] - past[1];
    w(v, ids[1]) = past[1] - past[2];
    w(v, ids[2]) = past[2];
  }

  const std::vector<std::vector<int>> nb = VertexNeighbours(mesh);
  for (int round = 0; round < options.smoothing_rounds; ++round) {
    SkinningWeights next = w;
    for (int v = 0; v < num_vertices; ++v) {
      if (nb[v].empty()) continue;
      Eigen::Matrix<double, 1, kNumHandJoints> avg =
          Eigen::Matrix<double, 1, kNumHandJoints>::Zero();
      for (int u : nb[v]) avg += w.row(u);
      next.row(v) = 0.5 * w.row(v) + 0.5 * avg / static_cast<double>(nb[v].size());
    }
    w = next;
  }
  for (int v = 0; v < num_vertices; ++v) {
    for (int j = 0; j < kNumHandJoints; ++j)
      if (w(v, j) < options.min_weight) w(v, j) = 0.0;
    w.row(v) /= w.row(v).sum();
  }
  return w;
}

}  // namespace handlabel
