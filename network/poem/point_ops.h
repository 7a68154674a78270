#pragma once
// Deterministic point operations of POEM on CPU: k-nearest neighbours, the ball
// selection of frustum points, gathers. Internal to network/ (includes LibTorch).
//
// Distances are squared Euclidean, evaluated in float as dx*dx + dy*dy + dz*dz (in
// that order, no fused multiply-add), so an independent implementation that follows
// the same rule selects exactly the same points. Ties go to the lower index.

#include <torch/torch.h>

namespace handlabel {

// query (B, Q, 3), points (B, P, 3), float32 -> (B, Q, k) int64 indices into points,
// nearest first (ties: lower index first). Each query includes itself if it is one of
// the points. Requires k <= P. Runs in parallel over queries (at::parallel_for).
torch::Tensor KnnIndices(const torch::Tensor& query, const torch::Tensor& points, int k);

// values (B, P, C), index (B, Q, k) -> (B, Q, k, C): values[b, index[b, q, j], :].
// Differentiable in `values`.
torch::Tensor GatherNeighbors(const torch::Tensor& values, const torch::Tensor& index);

// The ball selection rule (docs/network.md, "Point selection"):
// points (B, M, 3) in metres, center (B, 3); returns (B, count) int64 indices.
// Let I be the indices of the points with squared distance < radius^2 to the centre,
// in increasing order, and m = |I|.
//  - m >= count: the j-th selected point is I[floor(j * m / count)] (evenly spread over
//    the flattened frustum order, so every view and depth keeps its share);
//  - m < count: all of I, followed by the count - m nearest points outside the ball
//    (ties: lower index). No point is ever invented (the reference pads with the
//    origin, which is the master camera centre).
// `num_inside` (optional) receives m per batch element.
torch::Tensor SelectBallPoints(const torch::Tensor& points, const torch::Tensor& center,
                               double radius, int count,
                               std::vector<int64_t>* num_inside = nullptr);

// Bilinear samples of per-view feature maps, the same values as grid_sample (bilinear,
// zeros outside, align_corners false), written in the layout the view merge reads.
// features (B*N, C, H, W) float32, grid (B*N, P, 1, 2) in [-1, 1] (x, y) ->
// `per_view` (B, P, N, C). With `summed` (B*N, C', H, W) given, `summed_views`
// (B, P, C') is its samples at the same places summed over the views. Inference only
// (no gradient): it replaces grid_sample + permute + a copy, reading each sample's C
// channels as one contiguous row (the maps are read channels-last). A non-finite grid
// coordinate samples nothing (zeros).
struct ViewSamples {
  torch::Tensor per_view;
  torch::Tensor summed_views;
};
ViewSamples SampleViewsForMerge(const torch::Tensor& features, const torch::Tensor& grid,
                                int64_t B, int64_t N,
                                const torch::Tensor& summed = torch::Tensor());

// log(x / (1 - x)) after clamping x to [0, 1] and both x and 1 - x to >= eps.
torch::Tensor InverseSigmoid(const torch::Tensor& x, double eps = 1e-5);

}  // namespace handlabel
