// The optional mask head (PoemConfig::mask_head): shapes, loss, training it alone on
// frozen features, loading weights without it, and the masks' IoU bookkeeping.

#include <gtest/gtest.h>

#include <cmath>

#include "core/errors.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_training_batch.h"
#include "tests/network/poem/poem_test_util.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MakeSyntheticBatch;
using testing::MakeSyntheticTargets;

PoemConfig TinyWithMasks(int views) {
  PoemConfig c = TinyPoemConfig(views);
  c.mask_head = true;
  return c;
}

// Images with a bright disc per view and the disc's coverage on the mask grid, so a
// head on frozen features has something learnable.
void PaintDiscs(PoemBatch* batch, PoemTargets* targets) {
  const int64_t B = batch->images.size(0), N = batch->images.size(1);
  const int64_t S = batch->images.size(-1), M = S / 4;
  auto img = batch->images.accessor<float, 5>();
  torch::Tensor masks = torch::zeros({B, N, M, M});
  auto m = masks.accessor<float, 4>();
  for (int64_t b = 0; b < B; ++b) {
    for (int64_t n = 0; n < N; ++n) {
      const double cx = S * (0.3 + 0.1 * ((b + n) % 4)), cy = S * (0.6 - 0.07 * n);
      const double r = S * (0.15 + 0.03 * b);
      for (int64_t y = 0; y < S; ++y) {
        for (int64_t x = 0; x < S; ++x) {
          const bool in = std::hypot(x - cx, y - cy) < r;
          for (int c = 0; c < 3; ++c) img[b][n][c][y][x] = in ? 0.45f : -0.3f;
          if (in) m[b][n][y / 4][x / 4] += 1.0f / 16;
        }
      }
    }
  }
  targets->masks = masks;
}

TEST(PoemMaskHead, OnlyPresentWhenConfigured) {
  PoemModel plain = MakeRandomPoemModel(TinyPoemConfig(2), 4);
  PoemModel masked = MakeRandomPoemModel(TinyWithMasks(2), 4);
  const auto a = PoemStateDict(plain), b = PoemStateDict(masked);
  int head_keys = 0;
  for (const auto& [key, value] : b) {
    if (key.rfind("mask_head.", 0) == 0) {
      ++head_keys;
      continue;
    }
    ASSERT_TRUE(a.count(key)) << key;
    // The head is registered last: every other module gets the same random weights.
    EXPECT_TRUE(torch::equal(a.at(key), value)) << key;
  }
  EXPECT_EQ(a.size() + head_keys, b.size());
  EXPECT_GT(head_keys, 0);
  EXPECT_FALSE(plain->mask_head);
}

TEST(PoemMaskHead, ForwardGivesMaskLogitsAndLeavesTheMeshAlone) {
  const PoemConfig c = TinyWithMasks(3);
  PoemModel plain = MakeRandomPoemModel(TinyPoemConfig(3), 9);
  PoemModel masked = MakeRandomPoemModel(c, 9);
  plain->eval();
  masked->eval();
  torch::NoGradGuard g;
  const PoemBatch batch = MakeSyntheticBatch(c, 2, 5);
  const PoemOutputs a = plain->forward(batch);
  const PoemOutputs b = masked->forward(batch);
  EXPECT_FALSE(a.mask_logits.defined());
  ASSERT_TRUE(b.mask_logits.defined());
  EXPECT_EQ(b.mask_logits.sizes(),
            (std::vector<int64_t>{2, 3, c.mask_size(), c.mask_size()}));
  EXPECT_TRUE(torch::equal(a.layer_coords, b.layer_coords));
  EXPECT_TRUE(
      torch::equal(masked->MaskLogitsOnFrozenFeatures(batch.images), b.mask_logits));
}

TEST(PoemMaskHead, LossIsTheWrittenOutCrossEntropyAndJoinsTheTotal) {
  torch::manual_seed(3);
  const torch::Tensor logits = 3 * torch::randn({2, 3, 4, 4});
  const torch::Tensor coverage = torch::rand({2, 3, 4, 4});
  const torch::Tensor p = torch::sigmoid(logits);
  const double expected = -(coverage * torch::log(p) + (1 - coverage) * torch::log(1 - p))
                               .mean()
                               .item<double>();
  EXPECT_NEAR(PoemMaskLoss(logits, coverage).item<double>(), expected, 1e-5);

  const PoemConfig c = TinyWithMasks(2);
  PoemModel model = MakeRandomPoemModel(c, 2);
  model->eval();
  PoemBatch batch = MakeSyntheticBatch(c, 2, 1);
  PoemTargets targets = MakeSyntheticTargets(batch, 2);
  const torch::Tensor R = torch::rand({21, 778});
  const PoemOutputs out = model->forward(batch);
  const PoemLoss without = ComputePoemLoss(out, batch, targets, R);
  PaintDiscs(&batch, &targets);  // adds target masks (images are not re-run)
  PoemLossOptions o;
  o.mask_weight = 2.5;
  const PoemLoss with = ComputePoemLoss(out, batch, targets, R, o);
  double masks = -1;
  for (const auto& [name, value] : with.terms)
    if (name == "masks") masks = value.item<double>();
  ASSERT_GE(masks, 0);
  EXPECT_NEAR(masks, PoemMaskLoss(out.mask_logits, targets.masks).item<double>(), 1e-6);
  EXPECT_NEAR(with.total.item<double>(), without.total.item<double>() + 2.5 * masks,
              1e-4 * with.total.item<double>());
}

TEST(PoemMaskHead, TrainingTheHeadAloneLearnsAndFreezesEverythingElse) {
  const PoemConfig c = TinyWithMasks(2);
  PoemModel model = MakeRandomPoemModel(c, 11);
  std::map<std::string, torch::Tensor> before;
  for (const auto& [key, value] : PoemStateDict(model)) before[key] = value.clone();
  PoemBatch batch = MakeSyntheticBatch(c, 3, 4);
  PoemTargets targets = MakeSyntheticTargets(batch, 5);
  PaintDiscs(&batch, &targets);
  torch::optim::Adam adam(model->mask_head->parameters(),
                          torch::optim::AdamOptions(3e-2));
  std::vector<double> losses;
  for (int i = 0; i < 25; ++i)
    losses.push_back(TrainMaskHeadStep(model, adam, batch, targets).total);
  EXPECT_LT(losses.back(), 0.5 * losses.front());
  int changed = 0;
  for (const auto& [key, value] : PoemStateDict(model)) {
    const bool same = torch::equal(before.at(key), value);
    if (key.rfind("mask_head.", 0) == 0) {
      changed += !same;
    } else {
      EXPECT_TRUE(same) << key << " moved while training the mask head alone";
    }
  }
  EXPECT_GT(changed, 0);
}

TEST(PoemMaskHead, WeightsWithoutAHeadLoadOnlyWhenAsked) {
  const std::string dir = testing::ScratchDir();
  PoemModel plain = MakeRandomPoemModel(TinyPoemConfig(2), 21);
  SavePoemCheckpoint(plain, dir + "/plain.pt");
  PoemModel masked = MakeRandomPoemModel(TinyWithMasks(2), 22);
  const torch::Tensor head_before = masked->mask_head->parameters()[0].clone();
  EXPECT_THROW(LoadPoemCheckpointInto(masked, dir + "/plain.pt"), InputError);
  LoadPoemCheckpointInto(masked, dir + "/plain.pt", /*as_init_weights=*/true);
  const auto a = PoemStateDict(plain);
  for (const auto& [key, value] : PoemStateDict(masked)) {
    if (key.rfind("mask_head.", 0) == 0) continue;
    EXPECT_TRUE(torch::equal(a.at(key), value)) << key;
  }
  EXPECT_TRUE(torch::equal(masked->mask_head->parameters()[0], head_before));
  // And the head survives a round trip through an own checkpoint (config included).
  SavePoemCheckpoint(masked, dir + "/masked.pt");
  EXPECT_TRUE(ReadPoemCheckpointConfig(dir + "/masked.pt").mask_head);
  PoemModel back = LoadPoemCheckpoint(dir + "/masked.pt");
  EXPECT_TRUE(torch::equal(back->mask_head->parameters()[0], head_before));
  // A plain checkpoint's config says no head.
  EXPECT_FALSE(ReadPoemCheckpointConfig(dir + "/plain.pt").mask_head);
  // The other way round the head is dropped, and only when asked.
  PoemModel plain_again = MakeRandomPoemModel(TinyPoemConfig(2), 23);
  EXPECT_THROW(LoadPoemCheckpointInto(plain_again, dir + "/masked.pt"), InputError);
  LoadPoemCheckpointInto(plain_again, dir + "/masked.pt", /*as_init_weights=*/true);
  EXPECT_TRUE(torch::equal(PoemStateDict(plain_again).at("feat_in.conv.weight"),
                           PoemStateDict(back).at("feat_in.conv.weight")));
}

TEST(PoemMaskHead, ConfigJsonCarriesTheFlag) {
  const PoemConfig c = TinyWithMasks(4);
  const PoemConfig back = PoemConfig::FromJson(c.ToJson(), "test");
  EXPECT_TRUE(back.mask_head);
  EXPECT_TRUE(c.Differences(back).empty());
  // Older checkpoints have no field: no head.
  EXPECT_FALSE(PoemConfig::FromJson(R"({"num_views": 4})", "test").mask_head);
  EXPECT_EQ(TinyPoemConfig(4).Differences(c).size(), 1u);
  EXPECT_THROW(PoemConfig::FromJson(R"({"mask_head": "yes"})", "test"), InputError);
}

TEST(PoemMaskHead, PredictionsCarryProbabilitiesAndIouCountsCells) {
  const PoemConfig c = TinyWithMasks(2);
  PoemModel model = MakeRandomPoemModel(c, 6);
  TrainingSample sample;
  sample.joints_3d.setZero(21, 3);
  sample.vertices_3d.setZero(778, 3);
  const int S = c.crop_size, M = c.mask_size();
  for (int n = 0; n < 2; ++n) {
    TrainingView v;
    v.image.assign(3 * S * S, 0.1f * n);
    v.intrinsics << 2 * S, 0, S / 2.0, 0, 2 * S, S / 2.0, 0, 0, 1;
    if (n == 1) {
      Eigen::Matrix4d t = Eigen::Matrix4d::Identity();
      t(0, 3) = 0.2;
      v.master_from_cam = t;
    }
    v.mask.assign(S * S, 0.0f);
    for (int y = 0; y < S / 2; ++y)
      for (int x = 0; x < S; ++x) v.mask[y * S + x] = 1.0f;  // top half is hand
    sample.views.push_back(v);
  }
  const std::vector<PoemPrediction> pred = PredictPoem(model, {sample});
  ASSERT_EQ(pred[0].masks.size(), 2u);
  ASSERT_EQ(pred[0].masks[0].size(), static_cast<size_t>(M * M));
  // The probabilities are the sigmoid of the head's logits on these views, in view
  // order, row-major cells.
  torch::Tensor images = torch::empty({1, 2, 3, S, S});
  for (int n = 0; n < 2; ++n) {
    images[0][n].copy_(torch::from_blob(sample.views[n].image.data(), {3, S, S}));
  }
  model->eval();
  torch::Tensor expected;
  {
    torch::NoGradGuard no_grad;
    expected = torch::sigmoid(model->MaskLogitsOnFrozenFeatures(images));
  }
  ASSERT_EQ(expected.sizes(), (std::vector<int64_t>{1, 2, M, M}));
  auto e = expected.accessor<float, 4>();
  for (int n = 0; n < 2; ++n)
    for (int i = 0; i < M; ++i)
      for (int j = 0; j < M; ++j)
        ASSERT_NEAR(pred[0].masks[n][i * M + j], e[0][n][i][j], 1e-6) << n << i << j;
  // IoU by hand: predict the top quarter of rows -> 1/2 of the true half.
  std::vector<float> quarter(M * M, 0.0f);
  for (int i = 0; i < M / 4; ++i)
    for (int j = 0; j < M; ++j) quarter[i * M + j] = 0.9f;
  MaskIouCounts counts;
  counts.Add(quarter, sample.views[0].mask);
  EXPECT_DOUBLE_EQ(counts.Iou(), 0.5);
  counts.Add(std::vector<float>(M * M, 0.0f), std::vector<float>(S * S, 0.0f));
  EXPECT_DOUBLE_EQ(counts.Iou(), 0.5);  // empty views add nothing
  EXPECT_THROW(counts.Add(quarter, std::vector<float>(S * S - 1)), Error);
}

// The training target of each cell is the mean of the crop mask over its 4 x 4 block
// (a mask that varies along both axes catches transposed or shifted pooling).
TEST(PoemMaskHead, TargetsAreTheCropMasksBlockMeans) {
  const PoemConfig c = TinyWithMasks(2);
  const int S = c.crop_size, M = c.mask_size();
  TrainingSample sample;
  sample.joints_3d.setZero(21, 3);
  sample.vertices_3d.setZero(778, 3);
  for (int n = 0; n < 2; ++n) {
    TrainingView v;
    v.image.assign(3 * S * S, 0.0f);
    v.intrinsics << 2 * S, 0, S / 2.0, 0, 2 * S, S / 2.0, 0, 0, 1;
    v.mask.resize(S * S);
    for (int y = 0; y < S; ++y)
      for (int x = 0; x < S; ++x)
        v.mask[y * S + x] = std::fmod(0.37f * x + 0.11f * y * y + 0.5f * n, 1.0f);
    sample.views.push_back(v);
  }
  const PoemTrainingBatch tb = ToPoemTrainingBatch({sample});
  ASSERT_TRUE(tb.targets.masks.defined());
  ASSERT_EQ(tb.targets.masks.sizes(), (std::vector<int64_t>{1, 2, M, M}));
  auto t = tb.targets.masks.accessor<float, 4>();
  for (int n = 0; n < 2; ++n)
    for (int i = 0; i < M; ++i)
      for (int j = 0; j < M; ++j)
        ASSERT_NEAR(t[0][n][i][j], testing::BlockMean(sample.views[n].mask, S, i, j),
                    1e-6)
            << n << " " << i << " " << j;
}

}  // namespace
}  // namespace handlabel
