#include "network/hand_mesh_predictor.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "network/poem_model.h"
#include "tests/network/poem_test_util.h"

namespace handlabel {
namespace {

std::vector<HandMeshInput> ToInputs(const PoemBatch& b) {
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
  const auto predictions = predictor->Predict(ToInputs(batch));
  ASSERT_EQ(predictions.size(), 3u);

  PoemModel model = MakeRandomPoemModel(c, 21);
  model->eval();
  torch::NoGradGuard g;
  PoemBatch b = batch;
  // The predictor rebuilds master_from_cam from Rigid3 in double; feed the same.
  const auto frames = ToInputs(batch);
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

TEST(HandMeshPredictor, ValidatesFramesBeforeRunning) {
  HandMeshPredictorOptions o;
  o.config = "tiny";
  o.num_views = 2;
  o.num_threads = 1;
  auto predictor = CreateHandMeshPredictor(o);
  auto frames = ToInputs(testing::MakeSyntheticBatch(TinyPoemConfig(2), 1, 1));
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
