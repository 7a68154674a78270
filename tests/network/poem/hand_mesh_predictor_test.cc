#include "network/poem/hand_mesh_predictor.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"
#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

TEST(HandMeshPredictor, PoemFromCheckpointMatchesTheModel) {
  const PoemConfig c = TinyPoemConfig(2);
  const std::string path = testing::ScratchDir() + "/tiny.pt";
  WriteRandomPoemCheckpoint(c, 21, path);
  HandMeshPredictorOptions o;
  o.weights = path;
  o.num_threads = 1;
  o.batch_size = 2;
  auto predictor = CreateHandMeshPredictor(o);
  EXPECT_EQ(predictor->name(), "poem");
  EXPECT_EQ(predictor->num_views(), 2);
  EXPECT_EQ(predictor->crop_size(), 64);
  const PoemBatch batch = testing::MakeSyntheticBatch(c, 3, 4);
  const auto predictions = predictor->Predict(testing::ToInputs(batch));
  ASSERT_EQ(predictions.size(), 3u);

  PoemModel model = MakeRandomPoemModel(c, 21);
  model->eval();
  FoldNormsForInference(*model);  // as the predictor does
  torch::NoGradGuard g;
  PoemBatch b = batch;
  // The predictor rebuilds master_from_cam from Rigid3 in double; feed the same.
  const auto frames = testing::ToInputs(batch);
  for (int f = 0; f < 3; ++f)
    for (int n = 0; n < 2; ++n) {
      const Matrix3x4d m = frames[f].views[n].cam_from_master.Inverse().ToMatrix();
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 4; ++j)
          b.master_from_cam[f][n][i][j] = static_cast<float>(m(i, j));
    }
  const PoemOutputs out = model->forward(b);
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(predictions[f].vertices.rows(), 778);
    EXPECT_EQ(predictions[f].joints_2d.size(), 2u);
    for (int j = 0; j < 21; ++j)
      for (int a = 0; a < 3; ++a)
        EXPECT_NEAR(predictions[f].joints(j, a), out.joints()[f][j][a].item<float>(),
                    1e-6);
  }
}

TEST(HandMeshPredictor, MaskHeadProbabilitiesAreTheModelsSigmoid) {
  PoemConfig c = TinyPoemConfig(2);
  c.mask_head = true;
  const std::string path = testing::ScratchDir() + "/tiny_masks.pt";
  WriteRandomPoemCheckpoint(c, 8, path);
  HandMeshPredictorOptions o;
  o.weights = path;
  o.config = "tiny";  // a name with sizes: the head is an extra, not a mismatch
  o.num_views = 2;
  o.num_threads = 1;
  auto predictor = CreateHandMeshPredictor(o);
  EXPECT_TRUE(predictor->predicts_masks());
  const PoemBatch batch = testing::MakeSyntheticBatch(c, 2, 3);
  const auto predictions = predictor->Predict(testing::ToInputs(batch));
  PoemModel model = MakeRandomPoemModel(c, 8);
  model->eval();
  torch::NoGradGuard g;
  const torch::Tensor expected =
      torch::sigmoid(model->MaskLogitsOnFrozenFeatures(batch.images));
  const int M = c.mask_size();
  for (int f = 0; f < 2; ++f) {
    ASSERT_EQ(predictions[f].masks.size(), 2u);
    for (int n = 0; n < 2; ++n) {
      ASSERT_EQ(predictions[f].masks[n].rows(), M);
      for (int i = 0; i < M; i += 3)
        for (int j = 0; j < M; j += 5)
          EXPECT_NEAR(predictions[f].masks[n](i, j), expected[f][n][i][j].item<float>(),
                      1e-5);
    }
  }
  // Without a head: no masks.
  WriteRandomPoemCheckpoint(TinyPoemConfig(2), 8, path);
  auto plain = CreateHandMeshPredictor(o);
  EXPECT_FALSE(plain->predicts_masks());
  EXPECT_TRUE(plain->Predict(testing::ToInputs(batch))[0].masks.empty());
}

TEST(HandMeshPredictor, ValidatesFramesBeforeRunning) {
  HandMeshPredictorOptions o;
  o.config = "tiny";
  o.num_views = 2;
  o.num_threads = 1;
  auto predictor = CreateHandMeshPredictor(o);
  auto frames = testing::ToInputs(testing::MakeSyntheticBatch(TinyPoemConfig(2), 1, 1));
  auto bad = frames;
  bad[0].views.pop_back();
  EXPECT_THROW(predictor->Predict(bad), InputError);
  bad = frames;
  bad[0].views[1].pixels.resize(10);
  try {
    predictor->Predict(bad);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "frame 0 view 1");
    EXPECT_EQ(e.field(), "pixels");
  }
  bad = frames;
  bad[0].views[1].weight = 0;  // one view left: cannot triangulate
  EXPECT_THROW(predictor->Predict(bad), InputError);
  EXPECT_NO_THROW(predictor->Predict(frames));
}

TEST(HandMeshPredictor, RejectsBadOptionsAndMismatchedCheckpoint) {
  HandMeshPredictorOptions o;
  o.model = "metro";
  o.config = "tiny";
  EXPECT_THROW(CreateHandMeshPredictor(o), InputError);
  const std::string path = testing::ScratchDir() + "/tiny3.pt";
  WriteRandomPoemCheckpoint(TinyPoemConfig(3), 1, path);
  o = HandMeshPredictorOptions();
  o.weights = path;
  o.config = "tiny";
  o.num_views = 2;
  try {
    CreateHandMeshPredictor(o);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("num_views: 2 vs 3"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace handlabel
