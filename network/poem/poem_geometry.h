#pragma once
// Camera geometry inside POEM, in tensors (internal to network/, includes LibTorch):
// heatmap soft-argmax, weighted DLT triangulation, frustum points, projection into
// crops, the 3D sine encoding and the position-range normalisation.
//
// Conventions (docs/network.md): crop pixels use the reference's corner convention
// (feature cell j covers crop pixels [j*stride, (j+1)*stride) and is represented by
// j*stride); `master_from_cam` maps camera points to the master frame (metres, OpenCV
// axes); intrinsics are 3x3 crop intrinsics. Every function works on batches.

#include <torch/torch.h>

#include <array>

namespace handlabel {

// heatmaps (M, J, H, W), non-negative -> (M, J, 2) crop pixels (u, v):
// p = h / (sum h + 1e-6); u = sum_w (sum_h p) * w / W * crop_size; same for v.
torch::Tensor SoftArgmax2d(const torch::Tensor& heatmaps, int crop_size);

// uv (B, N, J, 2) pixels, intrinsics (B, N, 3, 3), cam_from_master (B, N, 4, 4),
// weights (B, N, J) or undefined (all ones) -> (B, J, 3) master-frame points.
// Rows u*P3 - P1 and v*P3 - P2 of view n are scaled by weights[b, n, j]; the solution
// is the last right singular vector, X = v[:3] / (v[3] + 1e-7).
torch::Tensor TriangulateDlt(const torch::Tensor& uv, const torch::Tensor& intrinsics,
                             const torch::Tensor& cam_from_master,
                             const torch::Tensor& weights = {});

// Frustum grid of every view in the master frame: (B, N, W, H, D, 3), where pixel
// (u, v) = (w, h) * crop_size / feature_size and depth z_d = zmin + d (zmax - zmin) / D.
torch::Tensor FrustumPoints(const torch::Tensor& intrinsics,
                            const torch::Tensor& master_from_cam, int feature_size,
                            int depth_bins, int crop_size, double zmin, double zmax);

// Per-axis (x - lo) / (hi - lo) with range = {xmin, ymin, zmin, xmax, ymax, zmax}.
torch::Tensor NormalizePositions(const torch::Tensor& xyz,
                                 const std::array<double, 6>& range);
torch::Tensor DenormalizePositions(const torch::Tensor& xyz,
                                   const std::array<double, 6>& range);

// Rigid transform of points (B, P, 3) by transforms (B, N, 4, 4) -> (B, N, P, 3),
// evaluated element-wise (R00 x + R01 y + R02 z + t0, ...), not through BLAS.
torch::Tensor TransformPoints(const torch::Tensor& transforms,
                              const torch::Tensor& points);

// Points (B, P, 3) in the master frame -> crop pixels (B, N, P, 2) of every view:
// cam_from_master, then the intrinsics, with |z| < 1e-7 replaced by 1e-7.
torch::Tensor ProjectPoints(const torch::Tensor& points, const torch::Tensor& intrinsics,
                            const torch::Tensor& cam_from_master);

// Points (B, P, 3) in the master frame -> grid_sample coordinates (B*N, P, 1, 2):
// project with cam_from_master and the intrinsics (|z| < 1e-7 becomes 1e-7), then
// uv / crop_size * 2 - 1.
torch::Tensor ProjectToGrid(const torch::Tensor& points, const torch::Tensor& intrinsics,
                            const torch::Tensor& cam_from_master, int crop_size);

// The reference's 3D sine encoding of an all-valid (view, y, x) volume:
// (num_views, 3 * num_feats, H, W), channel blocks (view, y, x), each num_feats / 2
// sines followed by num_feats / 2 cosines; positions (i + 1) / (n + 1e-6) * 2 pi,
// frequencies 10000^(2 floor(c / 2) / num_feats).
torch::Tensor SineEncoding3d(int num_views, int height, int width, int num_feats);

}  // namespace handlabel
