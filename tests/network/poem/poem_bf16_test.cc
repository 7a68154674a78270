// Reduced precision (network.precision: bf16, poem_modules.h ConvertToBf16ForInference):
// the converted products against a second formulation (inputs and weights rounded to
// bf16, multiplied in fp32 by plain ATen), and the shipped model's answers against fp32.

#include <gtest/gtest.h>

#include "core/errors.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"
#include "tests/network/poem/poem_test_util.h"

namespace handlabel {
namespace {

using testing::MaxAbsDiff;

torch::Tensor RoundedToBf16(const torch::Tensor& x) {
  return x.to(torch::kBFloat16).to(torch::kFloat);
}

// |got - want| within bf16's rounding of the result (half an ulp, 2^-9 relative) plus
// the fp32 accumulation's, elementwise.
void ExpectWithinOneBf16Rounding(const torch::Tensor& got, const torch::Tensor& want) {
  const torch::Tensor limit = want.abs() * std::ldexp(1.0, -8) + 1e-5;
  const torch::Tensor excess = ((got - want).abs() - limit).max();
  EXPECT_LE(excess.item<double>(), 0.0) << "largest difference " << MaxAbsDiff(got, want);
}

#define SKIP_WITHOUT_BF16()                            \
  if (!CpuCanRunBf16())                                \
  GTEST_SKIP() << "this CPU has no AVX-512 BW/VL/DQ: " \
                  "LibTorch's oneDNN cannot run bf16"

TEST(Bf16Inference, LinearIsTheProductOfRoundedInputsRoundedOnce) {
  SKIP_WITHOUT_BF16();
  torch::manual_seed(11);
  torch::NoGradGuard no_grad;
  torch::nn::Linear layer(torch::nn::LinearOptions(64, 48));
  const torch::Tensor x = torch::randn({799, 64});
  const torch::Tensor fp32 = InferenceLinear(*layer, x);
  const torch::Tensor want = torch::nn::functional::linear(
      RoundedToBf16(x), RoundedToBf16(layer->weight), RoundedToBf16(layer->bias));
  ConvertToBf16ForInference(*layer);
  ASSERT_EQ(layer->weight.scalar_type(), torch::kBFloat16);
  const torch::Tensor got = InferenceLinear(*layer, x);
  EXPECT_EQ(got.scalar_type(), torch::kFloat);  // the callers keep computing in fp32
  ExpectWithinOneBf16Rounding(got, want);
  EXPECT_GT(MaxAbsDiff(got, fp32), 0.0) << "the product did not run in bf16";
}

// An MLP in bf16 is the chain of rounded products (its hidden activations are the first
// product's bf16 results).
TEST(Bf16Inference, MlpIsTheChainOfRoundedProducts) {
  SKIP_WITHOUT_BF16();
  torch::manual_seed(13);
  torch::NoGradGuard no_grad;
  torch::nn::Sequential mlp = Mlp(3, 32, 16);
  auto* first = mlp[0]->as<torch::nn::Linear>();
  auto* second = mlp[2]->as<torch::nn::Linear>();
  const torch::Tensor x = torch::randn({2, 300, 3});
  namespace F = torch::nn::functional;
  const torch::Tensor hidden = RoundedToBf16(torch::relu(F::linear(
      RoundedToBf16(x), RoundedToBf16(first->weight), RoundedToBf16(first->bias))));
  const torch::Tensor want =
      F::linear(hidden, RoundedToBf16(second->weight), RoundedToBf16(second->bias));
  ConvertToBf16ForInference(*mlp);
  const torch::Tensor got = InferenceMlp(*mlp, x);
  EXPECT_EQ(got.scalar_type(), torch::kFloat);
  // The hidden values may round the other way where the two accumulation orders
  // straddle a bf16 boundary: a few output ulps, not more.
  EXPECT_LT(MaxAbsDiff(got, want),
            4 * std::ldexp(1.0, -8) * want.abs().max().item<double>());
}

TEST(Bf16Inference, PixelMlpIsTheChainOfRoundedProducts) {
  SKIP_WITHOUT_BF16();
  torch::manual_seed(14);
  torch::NoGradGuard no_grad;
  torch::nn::Conv2d first(torch::nn::Conv2dOptions(6, 20, 1)),
      second(torch::nn::Conv2dOptions(20, 12, 1));
  torch::nn::Sequential stack(first, torch::nn::ReLU(), second);
  const torch::Tensor x = torch::randn({3, 6, 9, 11});
  namespace F = torch::nn::functional;
  const torch::Tensor hidden = RoundedToBf16(
      torch::relu(F::conv2d(RoundedToBf16(x), RoundedToBf16(first->weight),
                            F::Conv2dFuncOptions().bias(RoundedToBf16(first->bias)))));
  const torch::Tensor want =
      F::conv2d(hidden, RoundedToBf16(second->weight),
                F::Conv2dFuncOptions().bias(RoundedToBf16(second->bias)));
  const torch::Tensor fp32 = RunPixelMlp(*stack, x);
  ConvertPixelConvToBf16(*first);
  ConvertPixelConvToBf16(*second);
  const torch::Tensor got = RunPixelMlp(*stack, x);
  EXPECT_EQ(got.scalar_type(), torch::kFloat);
  EXPECT_GT(MaxAbsDiff(got, fp32), 0) << "the products did not run in bf16";
  EXPECT_LT(MaxAbsDiff(got, want),
            4 * std::ldexp(1.0, -8) * want.abs().max().item<double>());
}

TEST(Bf16Inference, FoldedConvolutionIsTheConvolutionOfRoundedInputs) {
  SKIP_WITHOUT_BF16();
  torch::manual_seed(12);
  ConvBlock block(16, 24, 3, /*norm=*/true, /*relu=*/false);
  block->eval();
  FoldNormsForInference(*block);
  torch::NoGradGuard no_grad;
  const torch::Tensor x = torch::randn({2, 16, 20, 20});
  const FoldedConv& folded = block->folded;
  const torch::Tensor want = at::conv2d(RoundedToBf16(x), RoundedToBf16(folded.weight),
                                        RoundedToBf16(folded.bias), {1, 1}, {1, 1});
  ConvertToBf16ForInference(*block);
  const torch::Tensor got = block->forward(x);
  EXPECT_EQ(got.scalar_type(), torch::kFloat);
  ExpectWithinOneBf16Rounding(got, want);
}

const std::string kShipped =
    std::string(HANDLABEL_SOURCE_DIR) + "/models/poem_small_dexycb.pt";

std::vector<HandMeshPrediction> ShippedPredictions(const std::string& precision,
                                                   const std::vector<HandMeshInput>& in) {
  HandMeshPredictorOptions o;
  o.weights = kShipped;
  o.num_threads = 1;
  o.precision = precision;
  auto predictor = CreateHandMeshPredictor(o);
  EXPECT_EQ(predictor->precision(), precision);
  return predictor->Predict(in);
}

// On the 500-frame benchmarks bf16 moves MPJPE by less than their printed 0.01 mm
// (docs/speed.md). On these noise images the answers move by 0.5-1.1 mm on average
// (up to 12 mm where a point's ball or kNN selection flips): well under the
// centimetres that a wrong weight conversion or layout gives.
TEST(Bf16Inference, ShippedModelAnswersStayNearFp32) {
  SKIP_WITHOUT_BF16();
  const PoemConfig c = LoadPoemCheckpoint(kShipped)->config();
  const auto inputs = testing::ToInputs(testing::MakeSyntheticBatch(c, 2, 5));
  const auto fp32 = ShippedPredictions("fp32", inputs);
  const auto bf16 = ShippedPredictions("bf16", inputs);
  ASSERT_EQ(bf16.size(), fp32.size());
  for (size_t f = 0; f < fp32.size(); ++f) {
    const Eigen::VectorXd d = (bf16[f].vertices - fp32[f].vertices).rowwise().norm();
    EXPECT_LT(d.mean(), 2e-3) << "frame " << f;
    EXPECT_GT(d.maxCoeff(), 0.0)
        << "frame " << f << ": bf16 gave fp32's answer bit for bit";
  }
}

TEST(Bf16Inference, PrecisionIsCheckedAndAutoFollowsTheCpu) {
  HandMeshPredictorOptions o;
  o.config = "tiny";
  o.num_views = 2;
  o.precision = "fp16";
  EXPECT_THROW(o.Check("options"), InputError);
  EXPECT_EQ(ResolvePrecision("fp32"), "fp32");
  EXPECT_EQ(ResolvePrecision("auto"), CpuHasBf16Unit() ? "bf16" : "fp32");
  o.precision = "bf16";
  if (CpuCanRunBf16()) {
    EXPECT_EQ(CreateHandMeshPredictor(o)->precision(), "bf16");
  } else {
    EXPECT_THROW(CreateHandMeshPredictor(o), InputError);
  }
}

}  // namespace
}  // namespace handlabel
