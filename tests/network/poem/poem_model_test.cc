#include "network/poem/poem_model.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_trainer.h"
#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

using testing::MakeSyntheticBatch;
using testing::MakeSyntheticTargets;

TEST(PoemModel, TinyForwardShapesAndFiniteness) {
  const PoemConfig c = TinyPoemConfig(3);
  PoemModel model = MakeRandomPoemModel(c, 7);
  model->eval();
  torch::NoGradGuard g;
  const PoemOutputs out = model->forward(MakeSyntheticBatch(c, 2, 1));
  const int64_t H = c.heatmap_size();
  EXPECT_EQ(out.heatmaps.sizes(), (std::vector<int64_t>{2, 3, 21, H, H}));
  EXPECT_EQ(out.joints_2d.sizes(), (std::vector<int64_t>{2, 3, 21, 2}));
  EXPECT_EQ(out.triangulated_joints.sizes(), (std::vector<int64_t>{2, 21, 3}));
  EXPECT_EQ(out.initial_mesh.sizes(), (std::vector<int64_t>{2, 799, 3}));
  EXPECT_EQ(out.point_index.sizes(), (std::vector<int64_t>{2, c.num_sampled_points}));
  EXPECT_EQ(out.layer_coords.sizes(),
            (std::vector<int64_t>{c.num_decoder_blocks, 2, 799, 3}));
  EXPECT_TRUE(torch::isfinite(out.layer_coords).all().item<bool>());
  EXPECT_EQ(out.joints().sizes(), (std::vector<int64_t>{2, 21, 3}));
  EXPECT_EQ(out.vertices().sizes(), (std::vector<int64_t>{2, 778, 3}));
  // Initial vertices coincide at initialisation (1/21 weights, zero bias).
  const torch::Tensor v = out.initial_mesh.index({0, torch::indexing::Slice(21, 799)});
  EXPECT_LT((v - v[0]).abs().max().item<float>(), 1e-5);
}

TEST(PoemModel, StateDictKeysFollowTheReference) {
  PoemModel model(ReleasedPoemConfig(8));
  const auto sd = PoemStateDict(model);
  for (const char* key :
       {"img_backbone.conv1.weight",
        "img_backbone.bn1.running_var",
        "img_backbone.layer1.0.bn1.weight",
        "img_backbone.layer1.1.bn1.num_batches_tracked",
        "img_backbone.layer2.0.downsample.0.weight",
        "img_backbone.layer2.0.downsample.1.bias",
        "img_backbone.fc.weight",
        "uv_delayer.0.conv.weight",
        "uv_delayer.2.norm.running_mean",
        "uv_out.conv.bias",
        "uv_in.norm.weight",
        "feat_delayer.1.conv.weight",
        "feat_in.conv.weight",
        "linear_inv_skin.weight",
        "ptEmb_head.center_shift_layer.2.weight",
        "ptEmb_head.input_proj.weight",
        "ptEmb_head.adapt_pos3d.weight",
        "ptEmb_head.position_encoder.2.bias",
        "ptEmb_head.reference_embed.weight",
        "ptEmb_head.query_embedding.0.weight",
        "ptEmb_head.reg_branches.5.2.weight",
        "ptEmb_head.merge_net_feature.1.2.weight",
        "ptEmb_head.merge_net_query_feature.0.0.bias",
        "ptEmb_head.layer_global_feat.weight",
        "ptEmb_head.transformer.feats_self_attn.fc_delta.0.weight",
        "ptEmb_head.transformer.query_self_attn.5.w_qs.weight",
        "ptEmb_head.transformer.query_feats_cross_attn.0.fc_gamma.2.bias"}) {
    EXPECT_TRUE(sd.count(key)) << key;
  }
  // Frozen batch norm has no num_batches_tracked (first block of a stage, stem).
  EXPECT_FALSE(sd.count("img_backbone.layer1.0.bn1.num_batches_tracked"));
  EXPECT_FALSE(sd.count("img_backbone.bn1.num_batches_tracked"));
  EXPECT_FALSE(sd.count("ptEmb_head.transformer.query_self_attn.0.w_qs.bias"));
  EXPECT_EQ(sd.at("ptEmb_head.position_encoder.0.weight").sizes(),
            (std::vector<int64_t>{512, 96, 1, 1}));
  EXPECT_EQ(sd.at("ptEmb_head.adapt_pos3d.weight").sizes(),
            (std::vector<int64_t>{256, 384, 1, 1}));
  EXPECT_EQ(sd.at("uv_delayer.0.conv.weight").sizes(),
            (std::vector<int64_t>{256, 768, 3, 3}));
  int64_t params = 0;
  for (const auto& p : model->parameters()) params += p.numel();
  // About 35.4 M parameters in the released model (spec), without MANO buffers.
  EXPECT_GT(params, 34'000'000);
  EXPECT_LT(params, 36'500'000);
}

TEST(PoemModel, SameInputSameOutputBitwise) {
  const PoemConfig c = TinyPoemConfig(2);
  PoemModel model = MakeRandomPoemModel(c, 3);
  model->eval();
  torch::NoGradGuard g;
  const PoemBatch batch = MakeSyntheticBatch(c, 1, 2);
  const PoemOutputs a = model->forward(batch);
  const PoemOutputs b = model->forward(batch);
  EXPECT_TRUE(torch::equal(a.layer_coords, b.layer_coords));
  EXPECT_TRUE(torch::equal(a.point_index, b.point_index));
}

TEST(PoemModel, RejectsBatchOfOtherViewCount) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(3), 3);
  const PoemBatch batch = MakeSyntheticBatch(TinyPoemConfig(2), 1, 2);
  try {
    model->forward(batch);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "images");
  }
}

TEST(PoemCheckpoint, RoundTripGivesIdenticalOutputs) {
  const PoemConfig c = TinyPoemConfig(2);
  PoemModel model = MakeRandomPoemModel(c, 11);
  const std::string path = testing::ScratchDir() + "/tiny.pt";
  SavePoemCheckpoint(model, path);
  EXPECT_TRUE(ReadPoemCheckpointConfig(path).Differences(c).empty());
  PoemModel loaded = LoadPoemCheckpoint(path);
  model->eval();
  loaded->eval();
  torch::NoGradGuard g;
  const PoemBatch batch = MakeSyntheticBatch(c, 1, 5);
  EXPECT_TRUE(torch::equal(model->forward(batch).layer_coords,
                           loaded->forward(batch).layer_coords));
}

TEST(PoemCheckpoint, RefusesOtherConfigNamingTheDifference) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 11);
  const std::string path = testing::ScratchDir() + "/tiny.pt";
  SavePoemCheckpoint(model, path);
  PoemModel other(TinyPoemConfig(3));
  try {
    LoadPoemCheckpointInto(other, path);
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("num_views: 3 vs 2"), std::string::npos)
        << e.what();
  }
}

// Weights a run starts from may be of another view count (no parameter depends on
// it): every tensor arrives unchanged, while another difference is still refused.
TEST(PoemCheckpoint, InitWeightsOfAnotherViewCountLoadUnchanged) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 11);
  const std::string dir = testing::ScratchDir();
  const std::string path = dir + "/tiny_2views.pt";
  SavePoemCheckpoint(model, path);
  PoemModel three(TinyPoemConfig(3));
  LoadPoemCheckpointInto(three, path, /*as_init_weights=*/true);
  const auto saved = PoemStateDict(model);
  for (const auto& [key, value] : PoemStateDict(three)) {
    ASSERT_TRUE(saved.count(key)) << key;
    EXPECT_TRUE(torch::equal(value, saved.at(key))) << key;
  }
  EXPECT_EQ(three->config().num_views, 3);
  PoemConfig wider = TinyPoemConfig(3);
  wider.crop_size *= 2;
  PoemModel other(wider);
  EXPECT_THROW(LoadPoemCheckpointInto(other, path, /*as_init_weights=*/true), InputError);

  // The same weights written for a 3-camera rig (float16 storage): a checkpoint that
  // loads on its own, with every tensor the 2-view one rounded to half precision.
  const std::string converted = dir + "/tiny_3views.pt";
  WritePoemCheckpointForViews(path, 3, converted);
  EXPECT_EQ(ReadPoemCheckpointConfig(converted).num_views, 3);
  PoemModel loaded = LoadPoemCheckpoint(converted);
  for (const auto& [key, value] : PoemStateDict(loaded)) {
    ASSERT_TRUE(saved.count(key)) << key;
    const torch::Tensor expected = saved.at(key).to(torch::kHalf).to(value.dtype());
    EXPECT_TRUE(torch::equal(value, expected)) << key;
  }
}

TEST(PoemCheckpoint, StateDictMismatchListsKeysAndShapes) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 11);
  auto sd = PoemStateDict(model);
  sd.erase("linear_inv_skin.bias");
  sd["bogus.weight"] = torch::zeros({1});
  sd["ptEmb_head.input_proj.weight"] = torch::zeros({3, 3, 1, 1});
  try {
    LoadPoemStateDict(model, sd, "test.pth");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("linear_inv_skin.bias"), std::string::npos) << m;
    EXPECT_NE(m.find("bogus.weight"), std::string::npos) << m;
    EXPECT_NE(m.find("ptEmb_head.input_proj.weight (3, 3, 1, 1)"), std::string::npos)
        << m;
  }
}

TEST(PoemCheckpoint, RefusesNonFiniteWeightsNamingTheKey) {
  PoemModel model = MakeRandomPoemModel(TinyPoemConfig(2), 11);
  auto sd = PoemStateDict(model);
  sd["uv_out.conv.bias"] = sd["uv_out.conv.bias"].clone();
  sd["uv_out.conv.bias"][3] = NAN;
  try {
    LoadPoemStateDict(model, sd, "test.pth");
    FAIL() << "expected InputError";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "uv_out.conv.bias");
  }
}

TEST(PoemTrain, StepsReduceTheLossOnAFixedBatch) {
  const PoemConfig c = TinyPoemConfig(2);
  PoemModel model = MakeRandomPoemModel(c, 5);
  const PoemBatch batch = MakeSyntheticBatch(c, 2, 9);
  const PoemTargets targets = MakeSyntheticTargets(batch, 4);
  const torch::Tensor regressor = testing::MakeTestRegressor();
  torch::optim::Adam adam(model->parameters(), torch::optim::AdamOptions(1e-3));
  const TrainStepResult first = TrainStep(model, adam, batch, targets, regressor);
  TrainStepResult last = first;
  for (int i = 0; i < 8; ++i) last = TrainStep(model, adam, batch, targets, regressor);
  EXPECT_TRUE(std::isfinite(first.total));
  EXPECT_LT(last.total, first.total);
  EXPECT_EQ(first.terms.front().first, "heatmap_joints");
}

}  // namespace
}  // namespace handlabel
