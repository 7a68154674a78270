#include "network/poem/poem_training_batch.h"

#include <cstring>

#include "core/errors.h"

namespace handlabel {
namespace {

namespace F = torch::nn::functional;

// (B, N, S/4, S/4): the fraction of each 4 x 4 block of the S x S crop masks that is
// hand, the mask head's target.
torch::Tensor MaskCoverage(const std::vector<TrainingSample>& samples, int64_t S) {
  const int64_t B = samples.size(), N = samples[0].views.size();
  torch::Tensor masks = torch::empty({B * N, 1, S, S}, torch::kFloat32);
  float* dst = masks.data_ptr<float>();
  for (int64_t b = 0; b < B; ++b) {
    for (int64_t n = 0; n < N; ++n) {
      const std::vector<float>& mask = samples[b].views[n].mask;
      HL_CHECK(static_cast<int64_t>(mask.size()) == S * S,
               "every view of a batch needs an S x S mask, or none does");
      std::memcpy(dst + (b * N + n) * S * S, mask.data(), sizeof(float) * S * S);
    }
  }
  return F::avg_pool2d(masks, F::AvgPool2dFuncOptions(4).stride(4))
      .view({B, N, S / 4, S / 4});
}

}  // namespace

PoemTrainingBatch ToPoemTrainingBatch(const std::vector<TrainingSample>& samples) {
  HL_CHECK(!samples.empty(), "a batch needs samples");
  const int64_t B = samples.size();
  const int64_t N = samples[0].views.size();
  const int64_t S2 = samples[0].views[0].image.size() / 3;
  const int64_t S = static_cast<int64_t>(std::lround(std::sqrt(double(S2))));
  const int64_t V = samples[0].vertices_3d.rows();
  const auto f32 = torch::TensorOptions().dtype(torch::kFloat32);
  torch::Tensor images = torch::empty({B, N, 3, S, S}, f32);
  torch::Tensor K = torch::empty({B, N, 3, 3}, f32);
  torch::Tensor T = torch::empty({B, N, 4, 4}, f32);
  torch::Tensor j2d = torch::empty({B, N, 21, 2}, f32);
  torch::Tensor w2d = torch::empty({B, N, 21}, f32);
  torch::Tensor view_weights = torch::empty({B, N}, f32);
  bool all_views_weighted = true;
  torch::Tensor j3d = torch::empty({B, 21, 3}, f32);
  torch::Tensor v3d = torch::empty({B, V, 3}, f32);
  float* img = images.data_ptr<float>();
  auto k = K.accessor<float, 4>();
  auto t = T.accessor<float, 4>();
  auto uv = j2d.accessor<float, 4>();
  auto w = w2d.accessor<float, 3>();
  auto vw = view_weights.accessor<float, 2>();
  auto j = j3d.accessor<float, 3>();
  auto v = v3d.accessor<float, 3>();
  for (int64_t b = 0; b < B; ++b) {
    const TrainingSample& s = samples[b];
    HL_CHECK(static_cast<int64_t>(s.views.size()) == N, "equal view counts in a batch");
    HL_CHECK(s.vertices_3d.rows() == V && s.joints_3d.rows() == 21, "target sizes");
    for (int64_t n = 0; n < N; ++n) {
      const TrainingView& view = s.views[n];
      HL_CHECK(static_cast<int64_t>(view.image.size()) == 3 * S * S, "equal crop sizes");
      std::memcpy(img + ((b * N + n) * 3 * S * S), view.image.data(),
                  sizeof(float) * 3 * S * S);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c) k[b][n][r][c] = view.intrinsics(r, c);
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) t[b][n][r][c] = view.master_from_cam(r, c);
      for (int q = 0; q < 21; ++q) {
        uv[b][n][q][0] = view.joints_2d(q, 0);
        uv[b][n][q][1] = view.joints_2d(q, 1);
        w[b][n][q] = view.joints_2d_weight[q] * view.view_weight;
      }
      vw[b][n] = view.view_weight;
      all_views_weighted &= view.view_weight == 1.0f;
    }
    for (int q = 0; q < 21; ++q)
      for (int c = 0; c < 3; ++c) j[b][q][c] = s.joints_3d(q, c);
    for (int64_t q = 0; q < V; ++q)
      for (int c = 0; c < 3; ++c) v[b][q][c] = s.vertices_3d(q, c);
  }
  PoemTrainingBatch out;
  out.batch.images = images;
  out.batch.intrinsics = K;
  out.batch.master_from_cam = T;
  // Left undefined when every view counts fully: the model's unweighted path, as
  // before view weights existed.
  if (!all_views_weighted) out.batch.view_weights = view_weights;
  out.targets.joints_3d = j3d;
  out.targets.vertices_3d = v3d;
  out.targets.joints_2d = j2d;
  out.targets.joints_2d_weights = w2d;
  if (!samples[0].views[0].mask.empty()) out.targets.masks = MaskCoverage(samples, S);
  return out;
}

std::vector<PoemPrediction> PredictPoem(PoemModel& model,
                                        const std::vector<TrainingSample>& samples) {
  torch::NoGradGuard no_grad;
  model->eval();
  const PoemTrainingBatch tb = ToPoemTrainingBatch(samples);
  const PoemOutputs out = model->forward(tb.batch);
  const torch::Tensor joints = out.joints().to(torch::kFloat64).contiguous();
  const torch::Tensor verts = out.vertices().to(torch::kFloat64).contiguous();
  std::vector<PoemPrediction> result(samples.size());
  torch::Tensor masks;
  if (out.mask_logits.defined()) {
    masks = torch::sigmoid(out.mask_logits).to(torch::kFloat32).contiguous();
  }
  for (size_t b = 0; b < samples.size(); ++b) {
    if (masks.defined()) {
      const int64_t cells = masks.size(2) * masks.size(3);
      for (int64_t n = 0; n < masks.size(1); ++n) {
        const float* p = masks[b][n].data_ptr<float>();
        result[b].masks.emplace_back(p, p + cells);
      }
    }
    result[b].joints_3d =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
            joints[b].data_ptr<double>(), joints.size(1), 3);
    result[b].vertices_3d =
        Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
            verts[b].data_ptr<double>(), verts.size(1), 3);
  }
  return result;
}

}  // namespace handlabel
