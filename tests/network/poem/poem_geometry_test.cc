#include "network/poem/poem_geometry.h"

#include <gtest/gtest.h>

#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

using torch::indexing::Slice;

TEST(SoftArgmax, PeakGivesCellCornerInCropPixels) {
  torch::Tensor hm = torch::zeros({1, 2, 8, 8});
  hm[0][0][3][5] = 1;  // row 3, column 5
  hm[0][1][7][0] = 1;
  const torch::Tensor uv = SoftArgmax2d(hm, 64);
  EXPECT_NEAR(uv[0][0][0].item<float>(), 5 * 8, 1e-4);  // u = w / W * S
  EXPECT_NEAR(uv[0][0][1].item<float>(), 3 * 8, 1e-4);
  EXPECT_NEAR(uv[0][1][0].item<float>(), 0, 1e-4);
  EXPECT_NEAR(uv[0][1][1].item<float>(), 56, 1e-4);
}

TEST(TriangulateDlt, RecoversPointsAndIgnoresZeroWeightViews) {
  const PoemConfig c = TinyPoemConfig(4);
  const PoemBatch b = testing::MakeSyntheticBatch(c, 1, 3);
  const PoemTargets t = testing::MakeSyntheticTargets(b, 5);
  const torch::Tensor cam_from_master = torch::linalg_inv(b.master_from_cam);
  torch::Tensor uv = ProjectPoints(t.joints_3d, b.intrinsics, cam_from_master);
  EXPECT_LT((TriangulateDlt(uv, b.intrinsics, cam_from_master) - t.joints_3d)
                .abs()
                .max()
                .item<float>(),
            1e-4);
  // Corrupt view 2 and give it weight 0: the answer only uses the other views.
  uv.index_put_({0, 2}, uv.index({0, 2}) + 40.0);
  torch::Tensor w = torch::ones({1, 4, 21});
  w.index_put_({0, 2}, 0.0);
  EXPECT_LT((TriangulateDlt(uv, b.intrinsics, cam_from_master, w) - t.joints_3d)
                .abs()
                .max()
                .item<float>(),
            1e-4);
  EXPECT_GT((TriangulateDlt(uv, b.intrinsics, cam_from_master) - t.joints_3d)
                .abs()
                .max()
                .item<float>(),
            1e-3);
}

TEST(FrustumPoints, ProjectBackToTheirCellAndDepth) {
  const PoemConfig c = TinyPoemConfig(3);
  const PoemBatch b = testing::MakeSyntheticBatch(c, 1, 2);
  const int S = c.heatmap_size(), D = c.depth_bins;
  const double zmin = 0.2, zmax = 2.0;
  const torch::Tensor fr =
      FrustumPoints(b.intrinsics, b.master_from_cam, S, D, c.crop_size, zmin, zmax);
  ASSERT_EQ(fr.sizes(), (std::vector<int64_t>{1, 3, S, S, D, 3}));
  const torch::Tensor cam_from_master = torch::linalg_inv(b.master_from_cam);
  const double stride = static_cast<double>(c.crop_size) / S;
  for (int n = 0; n < 3; ++n) {
    for (int w : {0, 3, S - 1}) {
      for (int h : {0, 5}) {
        for (int d : {0, D - 1}) {
          const torch::Tensor p = fr.index({0, n, w, h, d}).view({1, 1, 3});
          const torch::Tensor uv = ProjectPoints(p, b.intrinsics, cam_from_master);
          EXPECT_NEAR(uv[0][n][0][0].item<float>(), w * stride, 1e-3);
          EXPECT_NEAR(uv[0][n][0][1].item<float>(), h * stride, 1e-3);
          const torch::Tensor pc = TransformPoints(cam_from_master, p.view({1, 1, 3}));
          EXPECT_NEAR(pc[0][n][0][2].item<float>(), zmin + d * (zmax - zmin) / D, 1e-5);
        }
      }
    }
  }
}

TEST(NormalizePositions, RoundTrips) {
  const std::array<double, 6> r = {-1.2, -1.2, 0.2, 1.2, 1.2, 2.0};
  const torch::Tensor x = torch::rand({2, 5, 3});
  const torch::Tensor n = NormalizePositions(x, r);
  EXPECT_TRUE(torch::allclose(DenormalizePositions(n, r), x, 1e-5, 1e-6));
  EXPECT_NEAR(NormalizePositions(torch::tensor({{{1.2f, -1.2f, 1.1f}}}), r)[0][0][0]
                  .item<float>(),
              1.0, 1e-6);
}

TEST(SineEncoding3d, LayoutIsViewYXWithSinesThenCosines) {
  const torch::Tensor e = SineEncoding3d(2, 3, 4, 8);
  ASSERT_EQ(e.sizes(), (std::vector<int64_t>{2, 24, 3, 4}));
  // View block, feature 0 (sine, lowest frequency) of view 1: sin((1+1)/(2+1e-6) 2 pi).
  EXPECT_NEAR(e[1][0][0][0].item<float>(), std::sin(2.0 / (2 + 1e-6) * 2 * M_PI), 1e-5);
  // Feature 4 is the first cosine.
  EXPECT_NEAR(e[0][4][0][0].item<float>(), std::cos(1.0 / (2 + 1e-6) * 2 * M_PI), 1e-5);
  // x block (channels 16..23), x = 2: frequency 10000^(2/8) for feature 1.
  EXPECT_NEAR(e[0][17][1][2].item<float>(),
              std::sin(3.0 / (4 + 1e-6) * 2 * M_PI / std::pow(10000.0, 2.0 / 8)), 1e-5);
}

}  // namespace
}  // namespace handlabel
