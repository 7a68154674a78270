#include "network/poem/poem_batch.h"

#include <algorithm>

#include "core/errors.h"

namespace handlabel {

PoemBatch MakePoemBatch(const std::vector<HandMeshInput>& frames, size_t begin,
                        size_t end, const PoemConfig& c) {
  HL_CHECK(begin <= end && end <= frames.size(), "frame range");
  const int64_t B = end - begin, N = c.num_views, S = c.crop_size;
  PoemBatch batch;
  batch.images = torch::empty({B, N, 3, S, S});
  batch.intrinsics = torch::empty({B, N, 3, 3});
  batch.master_from_cam = torch::empty({B, N, 4, 4});
  batch.view_weights = torch::empty({B, N});
  float* img = batch.images.data_ptr<float>();
  auto K = batch.intrinsics.accessor<float, 4>();
  auto T = batch.master_from_cam.accessor<float, 4>();
  auto W = batch.view_weights.accessor<float, 2>();
  for (int64_t b = 0; b < B; ++b) {
    const HandMeshInput& frame = frames[begin + b];
    HL_CHECK(static_cast<int64_t>(frame.views.size()) == N, "view count");
    for (int64_t n = 0; n < N; ++n) {
      const HandMeshViewInput& v = frame.views[n];
      HL_CHECK(static_cast<int64_t>(v.pixels.size()) == 3 * S * S, "crop size");
      std::copy(v.pixels.begin(), v.pixels.end(), img + (b * N + n) * 3 * S * S);
      const Matrix3x4d m = v.cam_from_master.Inverse().ToMatrix();
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
          K[b][n][i][j] = static_cast<float>(v.intrinsics(i, j));
        for (int j = 0; j < 4; ++j) T[b][n][i][j] = static_cast<float>(m(i, j));
      }
      for (int j = 0; j < 4; ++j) T[b][n][3][j] = j == 3 ? 1.0f : 0.0f;
      W[b][n] = static_cast<float>(v.weight);
    }
  }
  return batch;
}

PoemTargets MakePoemTargets(const std::vector<HandMeshTargets>& targets, size_t begin,
                            size_t end, const PoemConfig& c) {
  HL_CHECK(begin <= end && end <= targets.size(), "frame range");
  const int64_t B = end - begin, N = c.num_views, J = PoemConfig::kNumJoints;
  PoemTargets t;
  t.joints_3d = torch::empty({B, J, 3});
  t.vertices_3d = torch::empty({B, PoemConfig::kNumVertices, 3});
  t.joints_2d = torch::empty({B, N, J, 2});
  t.joints_2d_weights = torch::ones({B, N, J});
  auto j3 = t.joints_3d.accessor<float, 3>();
  auto v3 = t.vertices_3d.accessor<float, 3>();
  auto j2 = t.joints_2d.accessor<float, 4>();
  auto w2 = t.joints_2d_weights.accessor<float, 3>();
  for (int64_t b = 0; b < B; ++b) {
    const HandMeshTargets& g = targets[begin + b];
    const std::string src = "targets of frame " + std::to_string(begin + b);
    if (g.vertices.rows() != PoemConfig::kNumVertices) {
      throw InputError(src, "vertices", "778 rows", std::to_string(g.vertices.rows()));
    }
    if (static_cast<int64_t>(g.joints_2d.size()) != N) {
      throw InputError(src, "joints_2d", std::to_string(N) + " views",
                       std::to_string(g.joints_2d.size()));
    }
    if (!g.view_weights.empty() && static_cast<int64_t>(g.view_weights.size()) != N) {
      throw InputError(src, "view_weights", "empty or " + std::to_string(N) + " values",
                       std::to_string(g.view_weights.size()));
    }
    for (int64_t j = 0; j < J; ++j)
      for (int a = 0; a < 3; ++a) j3[b][j][a] = static_cast<float>(g.joints(j, a));
    for (int64_t v = 0; v < PoemConfig::kNumVertices; ++v)
      for (int a = 0; a < 3; ++a) v3[b][v][a] = static_cast<float>(g.vertices(v, a));
    for (int64_t n = 0; n < N; ++n) {
      const float w =
          g.view_weights.empty() ? 1.0f : static_cast<float>(g.view_weights[n]);
      for (int64_t j = 0; j < J; ++j) {
        j2[b][n][j][0] = static_cast<float>(g.joints_2d[n](j, 0));
        j2[b][n][j][1] = static_cast<float>(g.joints_2d[n](j, 1));
        w2[b][n][j] = w;
      }
    }
  }
  return t;
}

}  // namespace handlabel
