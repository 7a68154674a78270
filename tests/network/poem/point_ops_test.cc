#include "network/poem/point_ops.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

#include "tests/test_util.h"

namespace handlabel {
namespace {

// Brute force: sort all points by (distance, index).
std::vector<int64_t> BruteKnn(const torch::Tensor& q, const torch::Tensor& p, int k) {
  const auto qa = q.accessor<float, 1>();
  const auto pa = p.accessor<float, 2>();
  std::vector<std::pair<float, int64_t>> d;
  for (int64_t i = 0; i < p.size(0); ++i) {
    const float dx = qa[0] - pa[i][0], dy = qa[1] - pa[i][1], dz = qa[2] - pa[i][2];
    float s = dx * dx;
    s = s + dy * dy;
    s = s + dz * dz;
    d.emplace_back(s, i);
  }
  std::sort(d.begin(), d.end());
  std::vector<int64_t> out;
  for (int j = 0; j < k; ++j) out.push_back(d[j].second);
  return out;
}

TEST(Knn, MatchesBruteForceIncludingTies) {
  torch::manual_seed(testing::TestSeed());
  // Integer grid coordinates create many exact ties.
  const torch::Tensor points = torch::randint(0, 4, {2, 300, 3}).to(torch::kFloat32);
  const torch::Tensor query = torch::randint(0, 4, {2, 40, 3}).to(torch::kFloat32);
  const torch::Tensor knn = KnnIndices(query, points, 16);
  ASSERT_EQ(knn.sizes(), (std::vector<int64_t>{2, 40, 16}));
  for (int b = 0; b < 2; ++b) {
    for (int q = 0; q < 40; ++q) {
      const auto expected = BruteKnn(query[b][q], points[b], 16);
      for (int j = 0; j < 16; ++j) ASSERT_EQ(knn[b][q][j].item<int64_t>(), expected[j]);
    }
  }
}

TEST(Knn, MatchesBruteForceOnManyPointsWithDuplicates) {
  // Thousands of points (the block bound's regime) with every fourth point repeated
  // further on, so equal distances straddle the bound.
  torch::manual_seed(testing::TestSeed());
  torch::Tensor points = torch::rand({1, 3000, 3});
  points.index_put_({0, torch::indexing::Slice(2000, 2750)},
                    points.index({0, torch::indexing::Slice(0, 3000, 4)}));
  const torch::Tensor query = torch::rand({1, 60, 3});
  const torch::Tensor knn = KnnIndices(query, points, 24);
  for (int q = 0; q < 60; ++q) {
    const auto expected = BruteKnn(query[0][q], points[0], 24);
    for (int j = 0; j < 24; ++j) ASSERT_EQ(knn[0][q][j].item<int64_t>(), expected[j]);
  }
}

TEST(Knn, SelfQueryFindsItselfFirst) {
  torch::manual_seed(testing::TestSeed());
  const torch::Tensor points = torch::rand({1, 100, 3});
  const torch::Tensor knn = KnnIndices(points, points, 4);
  for (int i = 0; i < 100; ++i) EXPECT_EQ(knn[0][i][0].item<int64_t>(), i);
}

TEST(GatherNeighbors, PicksRowsPerBatch) {
  const torch::Tensor values =
      torch::arange(2 * 5 * 2).view({2, 5, 2}).to(torch::kFloat32);
  const torch::Tensor index = torch::tensor({{{4, 0}}, {{1, 1}}}, torch::kInt64);
  const torch::Tensor g = GatherNeighbors(values, index);
  EXPECT_TRUE(torch::equal(g[0][0][0], values[0][4]));
  EXPECT_TRUE(torch::equal(g[1][0][1], values[1][1]));
}

TEST(SelectBallPoints, SpreadsEvenlyOverInsidePoints) {
  // 1000 points on a line x = i mm; the ball of radius 0.1 m around x = 0.3005 m holds
  // indices 201..400 (200 points).
  torch::Tensor pts = torch::zeros({1, 1000, 3});
  for (int i = 0; i < 1000; ++i) pts[0][i][0] = i * 1e-3f;
  const torch::Tensor center = torch::tensor({{0.3005f, 0.f, 0.f}});
  std::vector<int64_t> inside;
  const torch::Tensor sel = SelectBallPoints(pts, center, 0.1, 50, &inside);
  ASSERT_EQ(inside[0], 200);
  std::vector<int64_t> got(sel.data_ptr<int64_t>(), sel.data_ptr<int64_t>() + 50);
  EXPECT_EQ(got.front(), 201);
  for (int j = 0; j < 50; ++j) EXPECT_EQ(got[j], 201 + 4 * j);
}

TEST(SelectBallPoints, FillsWithNearestOutsideNeverTheOrigin) {
  torch::Tensor pts = torch::zeros({1, 100, 3});
  for (int i = 0; i < 100; ++i) pts[0][i][0] = 1.0f + i * 0.01f;  // no point at origin
  const torch::Tensor center = torch::tensor({{1.503f, 0.f, 0.f}});
  std::vector<int64_t> inside;
  // radius 0.025: points 48..52 inside (5 points), 10 requested; the nearest outside
  // are 53, 47, 54, 46, 55.
  const torch::Tensor sel = SelectBallPoints(pts, center, 0.025, 10, &inside);
  EXPECT_EQ(inside[0], 5);
  std::vector<int64_t> got(sel.data_ptr<int64_t>(), sel.data_ptr<int64_t>() + 10);
  EXPECT_EQ(got, (std::vector<int64_t>{48, 49, 50, 51, 52, 53, 47, 54, 46, 55}));
}

// grid_sample (bilinear, zeros, align_corners false) on a (B*N, P, 1, 2) grid ->
// (B, N, C, P): the reference SampleViewsForMerge must reproduce.
torch::Tensor GridSampled(const torch::Tensor& maps, const torch::Tensor& grid, int64_t B,
                          int64_t N) {
  namespace F = torch::nn::functional;
  const torch::Tensor s = F::grid_sample(maps, grid,
                                         F::GridSampleFuncOptions()
                                             .mode(torch::kBilinear)
                                             .padding_mode(torch::kZeros)
                                             .align_corners(false));
  return s.reshape({B, N, maps.size(1), grid.size(1)});
}

TEST(SampleViewsForMerge, MatchesGridSampleInsideOnTheBorderAndOutside) {
  torch::manual_seed(testing::TestSeed());
  const int64_t B = 2, N = 3, P = 200, C = 19, Cs = 6, H = 7, W = 9;
  const torch::Tensor maps = torch::randn({B * N, C, H, W});
  // The second map channels-last in memory: the kernel must read either layout.
  const torch::Tensor summed =
      torch::randn({B * N, Cs, H, W}).contiguous(at::MemoryFormat::ChannelsLast);
  // Inside, outside by up to half the map, and exactly on pixel centres and edges.
  torch::Tensor grid = torch::rand({B * N, P, 1, 2}) * 3 - 1.5;
  grid.index_put_({torch::indexing::Slice(), torch::indexing::Slice(0, 4)},
                  torch::tensor({-1.f, 1.f, 1.f / W, -1.f + 1.f / H}).view({1, 4, 1, 1}));
  const ViewSamples got = SampleViewsForMerge(maps, grid, B, N, summed);
  const torch::Tensor want = GridSampled(maps, grid, B, N).permute({0, 3, 1, 2});
  const torch::Tensor want_sum = GridSampled(summed, grid, B, N).sum(1).transpose(1, 2);
  ASSERT_EQ(got.per_view.sizes(), (std::vector<int64_t>{B, P, N, C}));
  ASSERT_EQ(got.summed_views.sizes(), (std::vector<int64_t>{B, P, Cs}));
  EXPECT_LT((got.per_view - want).abs().max().item<float>(), 1e-5);
  EXPECT_LT((got.summed_views - want_sum).abs().max().item<float>(), 1e-5);
  // The test means something: some samples fall outside, some inside.
  const torch::Tensor zero = (want.abs().amax(-1) == 0);
  EXPECT_GT(zero.sum().item<int64_t>(), 0);
  EXPECT_LT(zero.sum().item<int64_t>(), B * P * N);
}

TEST(SampleViewsForMerge, NonFiniteCoordinatesSampleNothing) {
  const torch::Tensor maps = torch::ones({2, 4, 5, 5});
  const float inf = std::numeric_limits<float>::infinity();
  const torch::Tensor grid =
      torch::tensor({NAN, 0.f, 0.f, inf, -inf, 0.f, 1e30f, 1e30f, 0.f, 0.f})
          .view({1, 5, 2})
          .repeat({2, 1, 1})
          .view({2, 5, 1, 2});
  const torch::Tensor got = SampleViewsForMerge(maps, grid, 1, 2).per_view;  // (1,5,2,4)
  EXPECT_EQ(got.index({0, torch::indexing::Slice(0, 4)}).abs().max().item<float>(), 0);
  EXPECT_FLOAT_EQ(got[0][4][1][3].item<float>(), 1.f);
}

TEST(InverseSigmoid, InvertsSigmoidAndClamps) {
  const torch::Tensor x = torch::tensor({0.2f, 0.5f, 0.9f});
  EXPECT_TRUE(torch::allclose(torch::sigmoid(InverseSigmoid(x)), x, 1e-6, 1e-6));
  const torch::Tensor edge = InverseSigmoid(torch::tensor({-1.f, 2.f}));
  EXPECT_NEAR(edge[0].item<float>(), std::log(1e-5), 1e-3);
  EXPECT_NEAR(edge[1].item<float>(), -std::log(1e-5), 1e-3);
}

}  // namespace
}  // namespace handlabel
