// The inference kernels (oneDNN linears, chunked vector attention; poem_modules.h)
// against the modules' autograd path, which is the plain ATen formulation of the same
// math: they must agree to rounding.

#include <ATen/Parallel.h>
#include <gtest/gtest.h>

#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"
#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

using testing::MaxAbsDiff;

TEST(InferenceLinear, MatchesLinearForAnyRowCountAndShape) {
  torch::manual_seed(4);
  torch::NoGradGuard no_grad;
  for (const bool bias : {true, false}) {
    torch::nn::Linear layer(torch::nn::LinearOptions(24, 40).bias(bias));
    // 799 rows (no multiple of 16), a 3-d input, and a non-contiguous one.
    for (const torch::Tensor& x : {torch::randn({799, 24}), torch::randn({2, 13, 24}),
                                   torch::randn({24, 50}).t()}) {
      const torch::Tensor want = layer->forward(x);
      const torch::Tensor got = InferenceLinear(*layer, x);
      EXPECT_LT(MaxAbsDiff(got, want), 1e-5) << "bias " << bias << " " << x.sizes();
    }
  }
}

TEST(InferenceMlp, MatchesSequentialForward) {
  torch::manual_seed(5);
  torch::NoGradGuard no_grad;
  torch::nn::Sequential mlp = Mlp(3, 32, 16);
  const torch::Tensor x = torch::randn({2, 100, 7, 3});
  EXPECT_LT(MaxAbsDiff(InferenceMlp(*mlp, x), mlp->forward(x)), 1e-5);
}

TEST(InferenceMlp, MatchesSequentialForwardAcrossChunks) {
  // 3 x 1700 rows: more than one chunk of rows, the last one partial.
  torch::manual_seed(7);
  torch::NoGradGuard no_grad;
  torch::nn::Sequential mlp = Mlp(8, 32, 16);
  const torch::Tensor x = torch::randn({3, 1700, 8});
  const torch::Tensor got = InferenceMlp(*mlp, x);
  ASSERT_EQ(got.sizes(), (std::vector<int64_t>{3, 1700, 16}));
  EXPECT_LT(MaxAbsDiff(got, mlp->forward(x)), 1e-5);
}

TEST(PixelMlp, MatchesTheConvolutionsInEitherLayout) {
  torch::manual_seed(8);
  torch::nn::Sequential stack(torch::nn::Conv2d(torch::nn::Conv2dOptions(6, 20, 1)),
                              torch::nn::ReLU(),
                              torch::nn::Conv2d(torch::nn::Conv2dOptions(20, 12, 1)));
  const torch::Tensor x = torch::randn({3, 6, 9, 11});
  const torch::Tensor want = stack->forward(x);  // gradients recorded: the modules' path
  torch::NoGradGuard no_grad;
  for (const torch::Tensor& in : {x, x.contiguous(at::MemoryFormat::ChannelsLast)}) {
    const torch::Tensor got = RunPixelMlp(*stack, in);
    ASSERT_EQ(got.sizes(), want.sizes());
    EXPECT_LT(MaxAbsDiff(got, want), 1e-5);
  }
  torch::nn::Conv2d one(torch::nn::Conv2dOptions(6, 5, 1));
  EXPECT_LT(MaxAbsDiff(RunPixelConv(one, x), one->forward(x)), 1e-5);
}

// The chunked kernel against Attend() on B = 2 with more rows than one chunk, so
// chunks cross the batch boundary; 1 and 2 threads.
class AttentionKernel : public ::testing::TestWithParam<int> {};

TEST_P(AttentionKernel, SelfAndCrossAttentionMatchTheAutogradPath) {
  const int threads_before = at::get_num_threads();
  at::set_num_threads(GetParam());
  torch::manual_seed(6);
  const int64_t B = 2, Q = 301, P = 517, k = 16, dp = 24, d = 32;
  VectorAttention self_attn(dp, d, false), cross_attn(dp, d, true);
  const torch::Tensor qxyz = torch::rand({B, Q, 3}), pxyz = torch::rand({B, P, 3});
  const torch::Tensor qf = torch::randn({B, Q, dp}), pf = torch::randn({B, P, dp});
  const torch::Tensor self_knn = torch::randint(Q, {B, Q, k}, torch::kInt64);
  const torch::Tensor cross_knn = torch::randint(P, {B, Q, k}, torch::kInt64);
  // Autograd path: gradients are recorded (the training path).
  const torch::Tensor want_self = self_attn->SelfAttention(qxyz, qf, self_knn);
  const torch::Tensor want_cross =
      cross_attn->CrossAttention(qxyz, qf, pxyz, pf, cross_knn);
  ASSERT_TRUE(want_self.requires_grad());
  torch::NoGradGuard no_grad;
  ASSERT_TRUE(UseInferenceKernels());
  EXPECT_LT(MaxAbsDiff(self_attn->SelfAttention(qxyz, qf, self_knn), want_self), 1e-5);
  EXPECT_LT(
      MaxAbsDiff(cross_attn->CrossAttention(qxyz, qf, pxyz, pf, cross_knn), want_cross),
      1e-5);
  at::set_num_threads(threads_before);
}

INSTANTIATE_TEST_SUITE_P(Threads, AttentionKernel, ::testing::Values(1, 2));

// Random statistics and affine parameters for every batch norm under `module`.
void RandomizeNorms(torch::nn::Module& module) {
  torch::NoGradGuard no_grad;
  auto randomize = [](torch::Tensor gamma, torch::Tensor beta, torch::Tensor mean,
                      torch::Tensor var) {
    gamma.normal_(1.0, 0.5);
    beta.normal_(0.0, 0.5);
    mean.normal_(0.0, 0.5);
    var.uniform_(0.2, 3.0);
  };
  for (const auto& m : module.modules()) {
    if (auto* f = m->as<FrozenBatchNorm2d>()) {
      randomize(f->weight, f->bias, f->running_mean, f->running_var);
    } else if (auto* bn = m->as<torch::nn::BatchNorm2d>()) {
      randomize(bn->weight, bn->bias, bn->running_mean, bn->running_var);
    }
  }
}

// Folded conv + norm against conv then norm, written out here.
TEST(FoldConvNorm, EqualsTheConvolutionFollowedByTheNorm) {
  torch::manual_seed(10);
  torch::NoGradGuard no_grad;
  for (const bool conv_bias : {false, true}) {
    torch::nn::Conv2d conv(
        torch::nn::Conv2dOptions(5, 7, 3).stride(2).padding(1).bias(conv_bias));
    FrozenBatchNorm2d frozen(7);
    torch::nn::BatchNorm2d bn(torch::nn::BatchNorm2dOptions(7).eps(1e-3));
    RandomizeNorms(*frozen);
    RandomizeNorms(*bn);
    bn->eval();
    const torch::Tensor x = torch::randn({2, 5, 17, 12});
    const torch::Tensor y = conv(x);
    const torch::Tensor v = frozen->running_var.reshape({1, -1, 1, 1});
    const torch::Tensor m = frozen->running_mean.reshape({1, -1, 1, 1});
    const torch::Tensor want_frozen =
        (y - m) / (v + 1e-5).sqrt() * frozen->weight.reshape({1, -1, 1, 1}) +
        frozen->bias.reshape({1, -1, 1, 1});
    const torch::Tensor want_bn =
        (y - bn->running_mean.reshape({1, -1, 1, 1})) /
            (bn->running_var.reshape({1, -1, 1, 1}) + 1e-3).sqrt() *
            bn->weight.reshape({1, -1, 1, 1}) +
        bn->bias.reshape({1, -1, 1, 1});
    EXPECT_LT(MaxAbsDiff(FoldConvNorm(*conv, *frozen)(x), want_frozen), 1e-4);
    EXPECT_LT(MaxAbsDiff(FoldConvNorm(*conv, *bn)(x), want_bn), 1e-4);
    EXPECT_GT(MaxAbsDiff(want_bn, y), 0.1);  // the norm does something
  }
  torch::nn::BatchNorm2d training(7);
  torch::nn::Conv2d conv(torch::nn::Conv2dOptions(5, 7, 1));
  EXPECT_ANY_THROW(FoldConvNorm(*conv, *training));  // batch statistics: no fold
}

// The whole model: inference kernels vs the autograd path, and run-to-run identity;
// with the norms folded (as the predictor runs it) or not. Batch norms with random
// statistics, so that folding changes the weights.
class WholeModel : public ::testing::TestWithParam<bool> {};

TEST_P(WholeModel, InferenceKernelsMatchTheAutogradPath) {
  const PoemConfig c = SmallPoemConfig(3);
  PoemModel model = MakeRandomPoemModel(c, 8);
  RandomizeNorms(*model);
  model->eval();
  if (GetParam()) FoldNormsForInference(*model);
  const PoemBatch batch = testing::MakeSyntheticBatch(c, 1, 9);
  const PoemOutputs want = model->forward(batch);
  ASSERT_TRUE(want.layer_coords.requires_grad());
  torch::NoGradGuard no_grad;
  const PoemOutputs got = model->forward(batch);
  EXPECT_TRUE(torch::equal(got.point_index, want.point_index));
  // Unfolded: the same operations, bitwise or nearly. Folded: other rounding, which
  // this model turns into ~1.2e-5 m (as it does a 1e-6 relative change of the
  // images); the bound is the exactness required of the default mode (docs/speed.md).
  // Either can flip a k-nearest tie in the decoder (ExpectDecoderCoordsNear).
  const double bound = GetParam() ? 1e-4 : 1e-5;
  testing::ExpectDecoderCoordsNear(got.layer_coords, want.layer_coords.detach(), bound);
  EXPECT_TRUE(torch::equal(model->forward(batch).layer_coords, got.layer_coords));
}

INSTANTIATE_TEST_SUITE_P(FoldedNorms, WholeModel, ::testing::Bool());

}  // namespace
}  // namespace handlabel
