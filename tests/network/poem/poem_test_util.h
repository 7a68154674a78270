#pragma once
// Synthetic POEM inputs for tests: cameras on a ring looking at a hand-sized region
// in front of the master camera, random images, and ground truth near the centre.

#include <torch/torch.h>

#include <vector>

#include "geometry/rigid3.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_model.h"
#include "tests/test_util.h"

namespace handlabel::testing {

// Largest |a - b| (in doubles); a size mismatch fails the test and returns 1e30.
inline double MaxAbsDiff(const torch::Tensor& a, const torch::Tensor& b) {
  EXPECT_EQ(a.sizes(), b.sizes());
  if (a.sizes() != b.sizes()) return 1e30;
  return (a.to(torch::kFloat64) - b.to(torch::kFloat64)).abs().max().item<double>();
}

// Decoder coordinates (L, ...) of two runs that should agree to `bound` metres. A
// decoder point's neighbours are a k-nearest choice: where two distances differ by a
// rounding error, folded norms or another CPU's kernels (OpenBLAS picks them by CPU)
// can pick the other one and move that point (and, a layer later, its neighbours) by a
// few 1e-4. On a Zen 3 machine 3 of 4794 coordinates did in layer 0, 35 in layer 1;
// with OPENBLAS_CORETYPE=Sandybridge on a Zen 5 one moved 3.6e-4. A wrong weight or
// order moves them all, so: under 2 % of each layer's coordinates beyond `bound`, none
// beyond 1e-3.
inline void ExpectDecoderCoordsNear(const torch::Tensor& got, const torch::Tensor& want,
                                    double bound) {
  ASSERT_EQ(got.sizes(), want.sizes());
  for (int64_t l = 0; l < got.size(0); ++l) {
    EXPECT_LT(MaxAbsDiff(got[l], want[l]), 1e-3) << "decoder layer " << l;
    const torch::Tensor diff =
        (got[l].to(torch::kFloat64) - want[l].to(torch::kFloat64)).abs();
    const double far_share = (diff > bound).to(torch::kFloat64).mean().item<double>();
    EXPECT_LT(far_share, 0.02) << "decoder layer " << l;
  }
}

inline torch::Tensor ToTensor4x4(const Rigid3& r) {
  const Matrix3x4d m = r.ToMatrix();
  torch::Tensor t = torch::eye(4, torch::kFloat64);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 4; ++j) t[i][j] = m(i, j);
  return t.to(torch::kFloat32);
}

// Cameras 0.6 m from `center` (master frame), view 0 = master at the origin.
inline PoemBatch MakeSyntheticBatch(const PoemConfig& c, int batch_size, uint64_t seed) {
  torch::manual_seed(seed);
  const int N = c.num_views, S = c.crop_size;
  PoemBatch b;
  b.images = torch::rand({batch_size, N, 3, S, S}) - 0.5;
  b.intrinsics = torch::zeros({batch_size, N, 3, 3});
  b.master_from_cam = torch::zeros({batch_size, N, 4, 4});
  for (int i = 0; i < batch_size; ++i) {
    const Eigen::Vector3d center(0.02 * i, -0.01 * i, 0.6);
    for (int n = 0; n < N; ++n) {
      Rigid3 cam_from_master;
      if (n > 0) {
        const double a = 2 * M_PI * n / N;
        const Eigen::Vector3d eye =
            center +
            0.6 * Eigen::Vector3d(std::sin(a), 0.3 * std::cos(3 * a), -std::cos(a));
        cam_from_master = LookAt(eye, center, Eigen::Vector3d(0, -1, 0));
      }
      b.master_from_cam[i][n] = ToTensor4x4(cam_from_master.Inverse());
      const double f = 2.0 * S;
      b.intrinsics[i][n] = torch::tensor({{f, 0.0, S / 2.0 + 3.0 * n},
                                          {0.0, f * 1.01, S / 2.0 - 2.0 * n},
                                          {0.0, 0.0, 1.0}})
                               .to(torch::kFloat32);
    }
  }
  return b;
}

// Targets near the ring centre, consistent with the cameras.
inline PoemTargets MakeSyntheticTargets(const PoemBatch& b, uint64_t seed) {
  torch::manual_seed(seed);
  const int64_t B = b.images.size(0);
  PoemTargets t;
  torch::Tensor center = torch::zeros({B, 1, 3});
  for (int64_t i = 0; i < B; ++i) {
    center[i][0][0] = 0.02 * i;
    center[i][0][1] = -0.01 * i;
    center[i][0][2] = 0.6;
  }
  t.joints_3d = center + 0.05 * torch::randn({B, 21, 3});
  t.vertices_3d = center + 0.05 * torch::randn({B, 778, 3});
  // 2D targets: the projection of the 3D joints.
  const torch::Tensor cam_from_master = torch::linalg_inv(b.master_from_cam);
  t.joints_2d = torch::zeros({B, b.images.size(1), 21, 2});
  {
    torch::NoGradGuard g;
    const torch::Tensor R = cam_from_master.index(
        {"...", torch::indexing::Slice(0, 3), torch::indexing::Slice(0, 3)});
    const torch::Tensor tr =
        cam_from_master.index({"...", torch::indexing::Slice(0, 3), 3});
    const torch::Tensor pc =
        torch::matmul(t.joints_3d.unsqueeze(1), R.transpose(-1, -2)) + tr.unsqueeze(2);
    const torch::Tensor uvw = torch::matmul(pc, b.intrinsics.transpose(-1, -2));
    t.joints_2d = uvw.index({"...", torch::indexing::Slice(0, 2)}) /
                  uvw.index({"...", torch::indexing::Slice(2, 3)});
  }
  return t;
}

// A dense stand-in for a hand model's keypoint regressor: each keypoint averages a few
// vertices.
inline torch::Tensor MakeTestRegressor() {
  torch::Tensor r = torch::zeros({21, 778});
  for (int j = 0; j < 21; ++j)
    for (int k = 0; k < 4; ++k) r[j][(j * 37 + k * 11) % 778] = 0.25;
  return r;
}

// The torch-free frame structs of a batch (view weights 1).
inline std::vector<HandMeshInput> ToInputs(const PoemBatch& b) {
  std::vector<HandMeshInput> frames(b.images.size(0));
  const int64_t N = b.images.size(1);
  for (size_t f = 0; f < frames.size(); ++f) {
    for (int64_t n = 0; n < N; ++n) {
      HandMeshViewInput v;
      const torch::Tensor img = b.images[f][n].contiguous();
      v.pixels.assign(img.data_ptr<float>(), img.data_ptr<float>() + img.numel());
      Matrix3x4d m;
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j)
          v.intrinsics(i, j) = b.intrinsics[f][n][i][j].item<float>();
        for (int j = 0; j < 4; ++j) m(i, j) = b.master_from_cam[f][n][i][j].item<float>();
      }
      v.cam_from_master = Rigid3::FromMatrix(m).Inverse();
      frames[f].views.push_back(v);
    }
  }
  return frames;
}

// Mean of an S x S crop mask over the 4 x 4 block of mask-head cell (i, j), written
// out with loops as the independent reference for the head's targets and IoU.
inline double BlockMean(const std::vector<float>& mask, int S, int i, int j) {
  double sum = 0;
  for (int y = 4 * i; y < 4 * i + 4; ++y)
    for (int x = 4 * j; x < 4 * j + 4; ++x) sum += mask[y * S + x];
  return sum / 16;
}

}  // namespace handlabel::testing
