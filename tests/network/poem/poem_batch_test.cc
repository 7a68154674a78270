#include "network/poem/poem_batch.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "core/errors.h"
#include "network/poem/poem_loss.h"
#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

TEST(PoemBatch, FromFrameStructsReproducesTheTensors) {
  const PoemConfig c = TinyPoemConfig(3);
  const PoemBatch original = testing::MakeSyntheticBatch(c, 2, 7);
  auto frames = testing::ToInputs(original);
  frames[1].views[2].weight = 0;
  const PoemBatch b = MakePoemBatch(frames, 0, 2, c);
  EXPECT_TRUE(torch::equal(b.images, original.images));
  EXPECT_TRUE(torch::equal(b.intrinsics, original.intrinsics));
  EXPECT_TRUE(torch::allclose(b.master_from_cam, original.master_from_cam, 0, 1e-6));
  EXPECT_EQ(b.view_weights[1][2].item<float>(), 0.0f);
  EXPECT_EQ(b.view_weights[0][2].item<float>(), 1.0f);
}

TEST(PoemBatch, TargetsFromEigenAndOneTrainStep) {
  const PoemConfig c = TinyPoemConfig(2);
  const PoemBatch batch =
      MakePoemBatch(testing::ToInputs(testing::MakeSyntheticBatch(c, 1, 3)), 0, 1, c);
  HandMeshTargets g;
  g.joints = Keypoints3::Constant(0.1);
  g.joints.col(2).setConstant(0.6);
  g.vertices =
      Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>::Constant(778, 3, 0.6);
  g.joints_2d = {KeypointPixels::Constant(30), KeypointPixels::Constant(20)};
  g.view_weights = {1, 0};
  const PoemTargets t = MakePoemTargets({g}, 0, 1, c);
  EXPECT_FLOAT_EQ(t.joints_3d[0][4][2].item<float>(), 0.6f);
  EXPECT_FLOAT_EQ(t.joints_2d[0][1][3][0].item<float>(), 20.0f);
  EXPECT_FLOAT_EQ(t.joints_2d_weights[0][1][0].item<float>(), 0.0f);
  PoemModel model = MakeRandomPoemModel(c, 2);
  torch::optim::Adam adam(model->parameters(), torch::optim::AdamOptions(1e-4));
  torch::manual_seed(17);  // the forward pass samples points
  const TrainStepResult r =
      TrainStep(model, adam, batch, t, testing::MakeTestRegressor());
  EXPECT_TRUE(std::isfinite(r.total));

  // The reported loss is the loss of the weights before the step: a second model with
  // the same weights, run by hand in training mode with the same seed, gives it.
  PoemModel before = MakeRandomPoemModel(c, 2);
  before->train();
  torch::manual_seed(17);
  const PoemLoss expected =
      ComputePoemLoss(before->forward(batch), batch, t, testing::MakeTestRegressor());
  EXPECT_NEAR(r.total, expected.total.item<double>(),
              1e-5 * std::abs(expected.total.item<double>()));
  // Adam's first step moves every parameter with a gradient by about the learning rate
  // (m / sqrt(v) = sign of the gradient), never more.
  const auto after_w = model->named_parameters(), before_w = before->named_parameters();
  double largest = 0;
  int moved = 0;
  for (const auto& p : after_w) {
    const double d = (p.value() - before_w[p.key()]).abs().max().item<double>();
    largest = std::max(largest, d);
    moved += d > 0;
  }
  EXPECT_LE(largest, 1e-4 * 1.001);
  EXPECT_GE(largest, 1e-4 * 0.9);
  EXPECT_GT(moved, static_cast<int>(after_w.size()) / 2);

  g.joints_2d.pop_back();
  try {
    MakePoemTargets({g}, 0, 1, c);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "joints_2d");
  }
}

}  // namespace
}  // namespace handlabel
