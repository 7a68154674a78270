#include "network/poem/poem_geometry.h"

#include <cmath>

#include "core/errors.h"

namespace handlabel {
namespace {

using torch::indexing::Ellipsis;
using torch::indexing::None;
using torch::indexing::Slice;

// Entry (r, c) of a batch of matrices (..., R, C), keeping a trailing axis of size 1
// so it broadcasts against point lists (..., P).
torch::Tensor Entry(const torch::Tensor& m, int r, int c) {
  return m.index({Ellipsis, r, c}).unsqueeze(-1);
}

}  // namespace

torch::Tensor SoftArgmax2d(const torch::Tensor& heatmaps, int crop_size) {
  HL_CHECK(heatmaps.dim() == 4, "heatmaps must be (M, J, H, W)");
  const int64_t M = heatmaps.size(0), J = heatmaps.size(1);
  const int64_t H = heatmaps.size(2), W = heatmaps.size(3);
  torch::Tensor pdf = heatmaps.reshape({M, J, H * W});
  pdf = pdf / (pdf.sum(-1, /*keepdim=*/true) + 1e-6);
  pdf = pdf.view({M, J, H, W});
  const torch::Tensor v_acc = pdf.sum(3);  // (M, J, H)
  const torch::Tensor u_acc = pdf.sum(2);  // (M, J, W)
  const torch::Tensor wv = torch::arange(H, pdf.options()) / static_cast<double>(H);
  const torch::Tensor wu = torch::arange(W, pdf.options()) / static_cast<double>(W);
  const torch::Tensor v = (v_acc * wv).sum(-1, true);
  const torch::Tensor u = (u_acc * wu).sum(-1, true);
  return torch::cat({u, v}, -1) * static_cast<double>(crop_size);
}

torch::Tensor TriangulateDlt(const torch::Tensor& uv, const torch::Tensor& intrinsics,
                             const torch::Tensor& cam_from_master,
                             const torch::Tensor& weights) {
  const int64_t B = uv.size(0), N = uv.size(1), J = uv.size(2);
  // P = K [R | t]: (B, N, 3, 4)
  const torch::Tensor P =
      torch::matmul(intrinsics, cam_from_master.index({Ellipsis, Slice(0, 3), Slice()}));
  const torch::Tensor row2 = P.index({Ellipsis, Slice(2, 3), Slice()}).unsqueeze(2);
  const torch::Tensor rows01 = P.index({Ellipsis, Slice(0, 2), Slice()}).unsqueeze(2);
  // (B, N, J, 2, 4): uv_i * P3 - P_i
  torch::Tensor A = uv.unsqueeze(-1) * row2 - rows01;
  if (weights.defined()) A = A * weights.view({B, N, J, 1, 1});
  A = A.permute({0, 2, 1, 3, 4}).reshape({B * J, 2 * N, 4});
  const auto svd = torch::linalg_svd(A, /*full_matrices=*/true, c10::nullopt);
  const torch::Tensor vt = std::get<2>(svd);  // (BJ, 4, 4)
  const torch::Tensor last = vt.index({Slice(), -1, Slice()});
  const torch::Tensor X =
      last.index({Slice(), Slice(0, 3)}) / (last.index({Slice(), Slice(3, 4)}) + 1e-7);
  return X.reshape({B, J, 3});
}

torch::Tensor FrustumPoints(const torch::Tensor& intrinsics,
                            const torch::Tensor& master_from_cam, int feature_size,
                            int depth_bins, int crop_size, double zmin, double zmax) {
  const int64_t B = intrinsics.size(0), N = intrinsics.size(1);
  const int64_t S = feature_size, D = depth_bins;
  const auto opts = intrinsics.options();
  const double stride = static_cast<double>(crop_size) / feature_size;
  const torch::Tensor u = torch::arange(S, opts) * stride;  // along w
  const torch::Tensor v = torch::arange(S, opts) * stride;  // along h
  const torch::Tensor d = torch::arange(D, opts) * ((zmax - zmin) / D) + zmin;
  // Per view, broadcast over (W, H, D): shapes (B, N, W, 1, 1) etc.
  auto K = [&](int r, int c) {
    return intrinsics.index({Ellipsis, r, c}).view({B, N, 1, 1, 1});
  };
  const torch::Tensor uu = u.view({1, 1, S, 1, 1});
  const torch::Tensor vv = v.view({1, 1, 1, S, 1});
  const torch::Tensor dd = d.view({1, 1, 1, 1, D}).expand({B, N, S, S, D});
  const torch::Tensor x = (uu - K(0, 2)) / K(0, 0) * dd;
  const torch::Tensor y = (vv - K(1, 2)) / K(1, 1) * dd;
  const torch::Tensor z = dd;
  auto T = [&](int r, int c) {
    return master_from_cam.index({Ellipsis, r, c}).view({B, N, 1, 1, 1});
  };
  std::vector<torch::Tensor> out;
  for (int r = 0; r < 3; ++r) {
    out.push_back(T(r, 0) * x + T(r, 1) * y + T(r, 2) * z + T(r, 3));
  }
  return torch::stack(out, -1);
}

torch::Tensor NormalizePositions(const torch::Tensor& xyz,
                                 const std::array<double, 6>& r) {
  const auto opts = xyz.options();
  const torch::Tensor lo = torch::tensor({r[0], r[1], r[2]}, opts);
  const torch::Tensor span = torch::tensor({r[3] - r[0], r[4] - r[1], r[5] - r[2]}, opts);
  return (xyz - lo) / span;
}

torch::Tensor DenormalizePositions(const torch::Tensor& xyz,
                                   const std::array<double, 6>& r) {
  const auto opts = xyz.options();
  const torch::Tensor lo = torch::tensor({r[0], r[1], r[2]}, opts);
  const torch::Tensor span = torch::tensor({r[3] - r[0], r[4] - r[1], r[5] - r[2]}, opts);
  return xyz * span + lo;
}

torch::Tensor TransformPoints(const torch::Tensor& T, const torch::Tensor& points) {
  const int64_t B = T.size(0), P = points.size(1);
  const torch::Tensor x = points.index({Slice(), Slice(), 0}).view({B, 1, P});
  const torch::Tensor y = points.index({Slice(), Slice(), 1}).view({B, 1, P});
  const torch::Tensor z = points.index({Slice(), Slice(), 2}).view({B, 1, P});
  std::vector<torch::Tensor> out;
  for (int r = 0; r < 3; ++r) {
    out.push_back(Entry(T, r, 0) * x + Entry(T, r, 1) * y + Entry(T, r, 2) * z +
                  Entry(T, r, 3));
  }
  return torch::stack(out, -1);
}

torch::Tensor ProjectPoints(const torch::Tensor& points, const torch::Tensor& intrinsics,
                            const torch::Tensor& cam_from_master) {
  const torch::Tensor pc = TransformPoints(cam_from_master, points);  // (B, N, P, 3)
  const torch::Tensor x = pc.index({Ellipsis, 0});
  const torch::Tensor y = pc.index({Ellipsis, 1});
  const torch::Tensor z = pc.index({Ellipsis, 2});
  const torch::Tensor& K = intrinsics;
  const torch::Tensor pu = Entry(K, 0, 0) * x + Entry(K, 0, 1) * y + Entry(K, 0, 2) * z;
  const torch::Tensor pv = Entry(K, 1, 0) * x + Entry(K, 1, 1) * y + Entry(K, 1, 2) * z;
  torch::Tensor pw = Entry(K, 2, 0) * x + Entry(K, 2, 1) * y + Entry(K, 2, 2) * z;
  pw = torch::where(pw.abs() < 1e-7, torch::full_like(pw, 1e-7), pw);
  return torch::stack({pu / pw, pv / pw}, -1);
}

torch::Tensor ProjectToGrid(const torch::Tensor& points, const torch::Tensor& intrinsics,
                            const torch::Tensor& cam_from_master, int crop_size) {
  const int64_t B = points.size(0), N = intrinsics.size(1), P = points.size(1);
  const torch::Tensor uv = ProjectPoints(points, intrinsics, cam_from_master);
  return (uv / static_cast<double>(crop_size) * 2 - 1).reshape({B * N, P, 1, 2});
}

torch::Tensor SineEncoding3d(int num_views, int height, int width, int num_feats) {
  const double scale = 2 * M_PI;
  const double eps = 1e-6;
  const auto opts = torch::TensorOptions().dtype(torch::kFloat32);
  auto axis = [&](int n) {
    const torch::Tensor idx = torch::arange(1, n + 1, opts);
    return idx / (idx.index({Slice(-1, None)}) + eps) * scale;  // (n)
  };
  const torch::Tensor c = torch::arange(num_feats, opts);
  const torch::Tensor dim_t =
      torch::pow(10000.0, 2 * torch::div(c, 2, "floor") / static_cast<double>(num_feats));
  auto encode = [&](const torch::Tensor& pos) {  // (n) -> (n, num_feats)
    const torch::Tensor p = pos.unsqueeze(-1) / dim_t;
    return torch::cat({p.index({Slice(), Slice(0, None, 2)}).sin(),
                       p.index({Slice(), Slice(1, None, 2)}).cos()},
                      -1);
  };
  const torch::Tensor en = encode(axis(num_views)).view({num_views, 1, 1, num_feats});
  const torch::Tensor ey = encode(axis(height)).view({1, height, 1, num_feats});
  const torch::Tensor ex = encode(axis(width)).view({1, 1, width, num_feats});
  const std::vector<int64_t> full = {num_views, height, width, num_feats};
  return torch::cat({en.expand(full), ey.expand(full), ex.expand(full)}, -1)
      .permute({0, 3, 1, 2})
      .contiguous();
}

}  // namespace handlabel
