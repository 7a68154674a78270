// Each operator of the TFLite interpreter on a tiny model built in memory, against an
// independent plain-loop NHWC computation of TFLite's semantics (or hand-worked values).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "network/detector/tflite_model.h"
#include "tests/network/detector/tflite_test_util.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using namespace testing_tflite;

constexpr int kAdd = 0, kConcatenation = 2, kConv2d = 3, kDepthwise = 4, kDequantize = 6,
              kFullyConnected = 9, kLogistic = 14, kMaxPool = 17, kMul = 18,
              kReshape = 22, kResize = 23, kPad = 34, kMean = 40, kSub = 41, kPrelu = 54;

std::vector<float> RunOne(const std::string& bytes, const std::vector<float>& input) {
  auto model = TfliteModel::FromBytes(bytes, "fixture");
  return model->Run({input})[0];
}

void ExpectNear(const std::vector<float>& got, const std::vector<float>& want,
                float tol) {
  ASSERT_EQ(got.size(), want.size());
  for (size_t i = 0; i < got.size(); ++i) {
    ASSERT_NEAR(got[i], want[i], tol) << "element " << i;
  }
}

float Act(float x, int activation) {
  switch (activation) {
    case 1:
      return std::max(x, 0.0f);
    case 2:
      return std::min(std::max(x, -1.0f), 1.0f);
    case 3:
      return std::min(std::max(x, 0.0f), 6.0f);
    case 4:
      return std::tanh(x);
    default:
      return x;
  }
}

// TFLite output size and leading padding of one axis (the smaller half before).
struct Axis {
  int out, pad_before;
};
Axis SameOrValid(int in, int k, int stride, int dilation, bool valid) {
  const int k_eff = (k - 1) * dilation + 1;
  if (valid) return {(in - k_eff) / stride + 1, 0};
  const int out = (in + stride - 1) / stride;
  return {out, std::max((out - 1) * stride + k_eff - in, 0) / 2};
}

struct ConvCase {
  int h, w, c, out_c, k_h, k_w, stride_h, stride_w, dil_h, dil_w;
  bool valid;
  int activation;
  bool depthwise;
  bool fp16;
};

// Plain-loop NHWC convolution (depthwise: output channel = input channel * M + m).
std::vector<float> ReferenceConv(const ConvCase& p, const std::vector<float>& x,
                                 const std::vector<float>& filter,
                                 const std::vector<float>& bias) {
  const Axis ah = SameOrValid(p.h, p.k_h, p.stride_h, p.dil_h, p.valid);
  const Axis aw = SameOrValid(p.w, p.k_w, p.stride_w, p.dil_w, p.valid);
  const int multiplier = p.out_c / p.c;
  std::vector<float> y;
  for (int oy = 0; oy < ah.out; ++oy) {
    for (int ox = 0; ox < aw.out; ++ox) {
      for (int oc = 0; oc < p.out_c; ++oc) {
        double sum = bias[oc];
        for (int ky = 0; ky < p.k_h; ++ky) {
          for (int kx = 0; kx < p.k_w; ++kx) {
            const int iy = oy * p.stride_h - ah.pad_before + ky * p.dil_h;
            const int ix = ox * p.stride_w - aw.pad_before + kx * p.dil_w;
            if (iy < 0 || iy >= p.h || ix < 0 || ix >= p.w) continue;
            if (p.depthwise) {
              const int ic = oc / multiplier;
              sum += x[Nhwc(iy, ix, ic, p.w, p.c)] *
                     filter[(static_cast<size_t>(ky) * p.k_w + kx) * p.out_c + oc];
            } else {
              for (int ic = 0; ic < p.c; ++ic) {
                sum +=
                    x[Nhwc(iy, ix, ic, p.w, p.c)] *
                    filter[((static_cast<size_t>(oc) * p.k_h + ky) * p.k_w + kx) * p.c +
                           ic];
              }
            }
          }
        }
        y.push_back(Act(static_cast<float>(sum), p.activation));
      }
    }
  }
  return y;
}

void CheckConv(const ConvCase& p, std::mt19937& rng) {
  const Axis ah = SameOrValid(p.h, p.k_h, p.stride_h, p.dil_h, p.valid);
  const Axis aw = SameOrValid(p.w, p.k_w, p.stride_w, p.dil_w, p.valid);
  std::vector<int> filter_shape = p.depthwise
                                      ? std::vector<int>{1, p.k_h, p.k_w, p.out_c}
                                      : std::vector<int>{p.out_c, p.k_h, p.k_w, p.c};
  std::vector<float> filter =
      RandomFloats(p.k_h * p.k_w * p.out_c * (p.depthwise ? 1 : p.c), rng);
  const std::vector<float> bias = RandomFloats(p.out_c, rng);
  const std::vector<float> x = RandomFloats(p.h * p.w * p.c, rng);
  TfliteBuilder b;
  const int in = b.Tensor({1, p.h, p.w, p.c});
  int weights;
  if (p.fp16) {
    const int halves = b.ConstantHalf(filter_shape, filter);
    weights = b.Tensor(filter_shape);
    b.Op(kDequantize, {halves}, {weights});
    for (float& f : filter) f = HalfToFloat(FloatToHalf(f));  // what the file stores
  } else {
    weights = b.Constant(filter_shape, filter);
  }
  const int bias_t = b.Constant({p.out_c}, bias);
  const int out = b.Tensor({1, ah.out, aw.out, p.out_c});
  const auto padding = p.valid ? fb::Padding_VALID : fb::Padding_SAME;
  const auto act = static_cast<fb::ActivationFunctionType>(p.activation);
  if (p.depthwise) {
    b.Op(kDepthwise, {in, weights, bias_t}, {out},
         fb::BuiltinOptions_DepthwiseConv2DOptions,
         fb::CreateDepthwiseConv2DOptions(b.fbb(), padding, p.stride_w, p.stride_h,
                                          p.out_c / p.c, act, p.dil_w, p.dil_h)
             .Union());
  } else {
    b.Op(kConv2d, {in, weights, bias_t}, {out}, fb::BuiltinOptions_Conv2DOptions,
         fb::CreateConv2DOptions(b.fbb(), padding, p.stride_w, p.stride_h, act, p.dil_w,
                                 p.dil_h)
             .Union());
  }
  ExpectNear(RunOne(b.Finish({in}, {out}), x), ReferenceConv(p, x, filter, bias), 1e-4f);
}

TEST(TfliteOps, Conv2dMatchesLoopsForPaddingStrideDilationActivation) {
  std::mt19937 rng(7);
  // h, w, c, out_c, kh, kw, sh, sw, dh, dw, valid, activation, depthwise, fp16
  const ConvCase cases[] = {
      {7, 6, 3, 4, 3, 3, 1, 1, 1, 1, false, 0, false, false},
      {7, 8, 3, 5, 3, 3, 2, 2, 1, 1, false, 3, false, false},  // odd total padding
      {8, 8, 2, 3, 2, 2, 1, 1, 1, 1, false, 1, false, false},  // even kernel: pad after
      {9, 7, 2, 3, 3, 2, 2, 1, 1, 1, true, 2, false, false},
      {9, 9, 2, 2, 3, 3, 1, 1, 2, 2, false, 4, false, false},  // dilation
      {6, 5, 3, 2, 1, 1, 1, 1, 1, 1, false, 0, false, true},   // 1x1, fp16 weights
  };
  for (const ConvCase& p : cases) CheckConv(p, rng);
}

TEST(TfliteOps, DepthwiseConvMatchesLoopsWithMultiplier) {
  std::mt19937 rng(8);
  const ConvCase cases[] = {
      {7, 6, 3, 3, 3, 3, 1, 1, 1, 1, false, 3, true, false},
      {8, 7, 2, 4, 3, 3, 2, 2, 1, 1, false, 0, true, false},  // multiplier 2, stride 2
      {9, 9, 2, 2, 5, 5, 1, 1, 1, 1, false, 1, true, true},   // 5x5, fp16
      {9, 8, 3, 3, 3, 3, 1, 2, 2, 1, true, 0, true, false},   // VALID, dilation
  };
  for (const ConvCase& p : cases) CheckConv(p, rng);
}

TEST(TfliteOps, SamePaddingPutsTheOddPixelAfter) {
  // 1x3x1 input [1, 2, 3], 1x2 kernel of ones, SAME: total padding 1, all after, so
  // outputs are [1+2, 2+3, 3+0] (TFLite's split; a before-pad would give [1, 3, 5]).
  TfliteBuilder b;
  const int in = b.Tensor({1, 1, 3, 1});
  const int w = b.Constant({1, 1, 2, 1}, {1, 1});
  const int out = b.Tensor({1, 1, 3, 1});
  b.Op(kConv2d, {in, w, -1}, {out}, fb::BuiltinOptions_Conv2DOptions,
       fb::CreateConv2DOptions(b.fbb(), fb::Padding_SAME, 1, 1).Union());
  ExpectNear(RunOne(b.Finish({in}, {out}), {1, 2, 3}), {3, 5, 3}, 0);
}

TEST(TfliteOps, FullyConnectedFlattensInTfliteOrder) {
  std::mt19937 rng(9);
  // A conv (held NCHW inside) feeds the dense layer: flattening must use NHWC order.
  const int h = 3, w = 2, c = 2, out_features = 4;
  const std::vector<float> x = RandomFloats(h * w * c, rng);
  const std::vector<float> weights = RandomFloats(out_features * h * w * c, rng);
  const std::vector<float> bias = RandomFloats(out_features, rng);
  TfliteBuilder b;
  const int in = b.Tensor({1, h, w, c});
  const int identity = b.Constant({c, 1, 1, c}, {1, 0, 0, 1});
  const int conv = b.Tensor({1, h, w, c});
  b.Op(kConv2d, {in, identity, -1}, {conv}, fb::BuiltinOptions_Conv2DOptions,
       fb::CreateConv2DOptions(b.fbb(), fb::Padding_VALID, 1, 1).Union());
  const int wt = b.Constant({out_features, h * w * c}, weights);
  const int bt = b.Constant({out_features}, bias);
  const int out = b.Tensor({1, out_features});
  b.Op(kFullyConnected, {conv, wt, bt}, {out}, fb::BuiltinOptions_FullyConnectedOptions,
       fb::CreateFullyConnectedOptions(b.fbb(), fb::ActivationFunctionType_RELU).Union());
  std::vector<float> want;
  for (int o = 0; o < out_features; ++o) {
    double sum = bias[o];
    for (int i = 0; i < h * w * c; ++i) sum += weights[o * h * w * c + i] * x[i];
    want.push_back(std::max(static_cast<float>(sum), 0.0f));
  }
  ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 1e-5f);
}

// conv(identity) so the value is held NCHW, then a binary op with a per-channel constant.
TEST(TfliteOps, BinaryOpsBroadcastAndFuseActivations) {
  std::mt19937 rng(10);
  const int h = 3, w = 4, c = 3;
  const std::vector<float> x = RandomFloats(h * w * c, rng, -3, 3);
  const std::vector<float> per_channel = RandomFloats(c, rng, 0.5, 2);
  for (int code : {kAdd, kSub, kMul}) {
    TfliteBuilder b;
    const int in = b.Tensor({1, h, w, c});
    std::vector<float> eye(c * c, 0);
    for (int i = 0; i < c; ++i) eye[i * c + i] = 1;
    const int conv = b.Tensor({1, h, w, c});
    b.Op(kConv2d, {in, b.Constant({c, 1, 1, c}, eye), -1}, {conv},
         fb::BuiltinOptions_Conv2DOptions,
         fb::CreateConv2DOptions(b.fbb(), fb::Padding_VALID, 1, 1).Union());
    const int k = b.Constant({c}, per_channel);
    const int sum = b.Tensor({1, h, w, c});
    const int out = b.Tensor({1, h, w, c});
    // conv (NCHW) op constant, then the result op the raw input (TFLite order).
    const auto relu6 = fb::ActivationFunctionType_RELU6;
    if (code == kAdd) {
      b.Op(code, {conv, k}, {sum}, fb::BuiltinOptions_AddOptions,
           fb::CreateAddOptions(b.fbb(), relu6).Union());
    } else if (code == kSub) {
      b.Op(code, {conv, k}, {sum}, fb::BuiltinOptions_SubOptions,
           fb::CreateSubOptions(b.fbb(), relu6).Union());
    } else {
      b.Op(code, {conv, k}, {sum}, fb::BuiltinOptions_MulOptions,
           fb::CreateMulOptions(b.fbb(), relu6).Union());
    }
    b.Op(kAdd, {sum, in}, {out});
    std::vector<float> want;
    for (size_t i = 0; i < x.size(); ++i) {
      const float kc = per_channel[i % c];
      const float r = code == kAdd ? x[i] + kc : code == kSub ? x[i] - kc : x[i] * kc;
      want.push_back(Act(r, 3) + x[i]);
    }
    ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 1e-5f);
  }
}

TEST(TfliteOps, MeanOverAxesWithAndWithoutKeepDims) {
  std::mt19937 rng(11);
  const int h = 3, w = 4, c = 2;
  const std::vector<float> x = RandomFloats(h * w * c, rng);
  for (bool keep : {false, true}) {
    for (const std::vector<int32_t>& axes :
         {std::vector<int32_t>{1, 2}, std::vector<int32_t>{-1},
          std::vector<int32_t>{2}}) {
      TfliteBuilder b;
      const int in = b.Tensor({1, h, w, c});
      const int relu = b.Tensor({1, h, w, c});
      // MAX_POOL 1x1 holds the value NCHW inside, so the axes mapping is exercised.
      b.Op(kMaxPool, {in}, {relu}, fb::BuiltinOptions_Pool2DOptions,
           fb::CreatePool2DOptions(b.fbb(), fb::Padding_VALID, 1, 1, 1, 1).Union());
      std::vector<int> out_shape;
      const std::vector<int> dims{1, h, w, c};
      for (int d = 0; d < 4; ++d) {
        const bool reduced = std::count(axes.begin(), axes.end(), d) +
                             std::count(axes.begin(), axes.end(), d - 4);
        if (!reduced) out_shape.push_back(dims[d]);
        if (reduced && keep) out_shape.push_back(1);
      }
      const int out = b.Tensor(out_shape);
      b.Op(kMean, {relu, b.ConstantInt({static_cast<int>(axes.size())}, axes)}, {out},
           fb::BuiltinOptions_ReducerOptions,
           fb::CreateReducerOptions(b.fbb(), keep).Union());
      // Plain loops: average over the reduced axes, output in row-major order.
      std::vector<double> sums;
      std::vector<int> counts;
      std::vector<size_t> index_of;
      auto reduced = [&](int d) {
        return std::count(axes.begin(), axes.end(), d) +
                   std::count(axes.begin(), axes.end(), d - 4) >
               0;
      };
      size_t out_size = 1;
      for (int d = 1; d < 4; ++d) out_size *= reduced(d) ? 1 : dims[d];
      sums.assign(out_size, 0);
      counts.assign(out_size, 0);
      for (int y = 0; y < h; ++y) {
        for (int xx = 0; xx < w; ++xx) {
          for (int ch = 0; ch < c; ++ch) {
            size_t o = 0;
            const int idx[] = {0, y, xx, ch};
            for (int d = 1; d < 4; ++d)
              o = o * (reduced(d) ? 1 : dims[d]) + (reduced(d) ? 0 : idx[d]);
            sums[o] += x[Nhwc(y, xx, ch, w, c)];
            counts[o]++;
          }
        }
      }
      std::vector<float> want;
      for (size_t i = 0; i < out_size; ++i)
        want.push_back(static_cast<float>(sums[i] / counts[i]));
      ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 1e-5f);
    }
  }
}

TEST(TfliteOps, LogisticAndPrelu) {
  std::mt19937 rng(12);
  const int h = 2, w = 3, c = 4;
  const std::vector<float> x = RandomFloats(h * w * c, rng, -4, 4);
  const std::vector<float> alpha = RandomFloats(c, rng, 0, 0.5);
  TfliteBuilder b;
  const int in = b.Tensor({1, h, w, c});
  const int pooled = b.Tensor({1, h, w, c});
  b.Op(kMaxPool, {in}, {pooled}, fb::BuiltinOptions_Pool2DOptions,
       fb::CreatePool2DOptions(b.fbb(), fb::Padding_VALID, 1, 1, 1, 1).Union());
  const int alpha_t = b.ConstantHalf({1, 1, c}, alpha);
  const int alpha_f = b.Tensor({1, 1, c});
  b.Op(kDequantize, {alpha_t}, {alpha_f});
  const int prelu = b.Tensor({1, h, w, c});
  b.Op(kPrelu, {pooled, alpha_f}, {prelu});
  const int out = b.Tensor({1, h, w, c});
  b.Op(kLogistic, {prelu}, {out});
  std::vector<float> want;
  for (size_t i = 0; i < x.size(); ++i) {
    const float a = HalfToFloat(FloatToHalf(alpha[i % c]));
    const float p = x[i] >= 0 ? x[i] : a * x[i];
    want.push_back(1.0f / (1.0f + std::exp(-p)));
  }
  ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 1e-6f);
}

TEST(TfliteOps, PreluWithComputedAlphaAndOnRank3) {
  // The general path: alpha is a graph input (not a constant), x of rank 3.
  std::mt19937 rng(17);
  const int h = 3, c = 4;
  const std::vector<float> x = RandomFloats(h * c, rng, -2, 2);
  const std::vector<float> alpha = RandomFloats(c, rng, 0, 0.5);
  TfliteBuilder b;
  const int in = b.Tensor({1, h, c});
  const int alpha_in = b.Tensor({c});
  const int out = b.Tensor({1, h, c});
  b.Op(kPrelu, {in, alpha_in}, {out});
  auto model = TfliteModel::FromBytes(b.Finish({in, alpha_in}, {out}), "fixture");
  std::vector<float> want;
  for (size_t i = 0; i < x.size(); ++i)
    want.push_back(x[i] >= 0 ? x[i] : alpha[i % c] * x[i]);
  ExpectNear(model->Run({x, alpha})[0], want, 1e-6f);
}

TEST(TfliteOps, PadSpatialAndChannels) {
  std::mt19937 rng(13);
  const int h = 2, w = 3, c = 2;
  const std::vector<float> x = RandomFloats(h * w * c, rng);
  // paddings [[0,0],[1,0],[0,2],[1,3]]: H before 1, W after 2, C before 1 after 3.
  const std::vector<int32_t> pads{0, 0, 1, 0, 0, 2, 1, 3};
  const int oh = h + 1, ow = w + 2, oc = c + 4;
  for (bool nchw_inside : {false, true}) {
    TfliteBuilder b;
    const int in = b.Tensor({1, h, w, c});
    int src = in;
    if (nchw_inside) {
      src = b.Tensor({1, h, w, c});
      b.Op(kMaxPool, {in}, {src}, fb::BuiltinOptions_Pool2DOptions,
           fb::CreatePool2DOptions(b.fbb(), fb::Padding_VALID, 1, 1, 1, 1).Union());
    }
    const int out = b.Tensor({1, oh, ow, oc});
    b.Op(kPad, {src, b.ConstantInt({4, 2}, pads)}, {out}, fb::BuiltinOptions_PadOptions,
         fb::CreatePadOptions(b.fbb()).Union());
    std::vector<float> want(oh * ow * oc, 0.0f);
    for (int y = 0; y < h; ++y)
      for (int xx = 0; xx < w; ++xx)
        for (int ch = 0; ch < c; ++ch)
          want[Nhwc(y + 1, xx, ch + 1, ow, oc)] = x[Nhwc(y, xx, ch, w, c)];
    ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 0);
  }
}

TEST(TfliteOps, MaxPoolSameIgnoresPaddingAndValid) {
  std::mt19937 rng(14);
  // All-negative input: a zero-padded pool would return 0 at the border.
  const int h = 5, w = 5, c = 2;
  const std::vector<float> x = RandomFloats(h * w * c, rng, -5, -1);
  for (bool valid : {false, true}) {
    for (int k : {2, 3}) {
      const Axis a = SameOrValid(h, k, 2, 1, valid);
      TfliteBuilder b;
      const int in = b.Tensor({1, h, w, c});
      const int out = b.Tensor({1, a.out, a.out, c});
      b.Op(kMaxPool, {in}, {out}, fb::BuiltinOptions_Pool2DOptions,
           fb::CreatePool2DOptions(b.fbb(), valid ? fb::Padding_VALID : fb::Padding_SAME,
                                   2, 2, k, k)
               .Union());
      std::vector<float> want;
      for (int oy = 0; oy < a.out; ++oy)
        for (int ox = 0; ox < a.out; ++ox)
          for (int ch = 0; ch < c; ++ch) {
            float m = -std::numeric_limits<float>::infinity();
            for (int ky = 0; ky < k; ++ky)
              for (int kx = 0; kx < k; ++kx) {
                const int iy = oy * 2 - a.pad_before + ky,
                          ix = ox * 2 - a.pad_before + kx;
                if (iy >= 0 && iy < h && ix >= 0 && ix < w)
                  m = std::max(m, x[Nhwc(iy, ix, ch, w, c)]);
              }
            want.push_back(m);
          }
      ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 0);
    }
  }
}

// TFLite's reference RESIZE_BILINEAR: four neighbours, floor/ceil clamped.
std::vector<float> ReferenceResize(const std::vector<float>& x, int h, int w, int c,
                                   int oh, int ow, bool align, bool half) {
  auto source = [&](int i, int in, int out, float* frac, int* lo, int* hi) {
    const float scale = (align && out > 1) ? static_cast<float>(in - 1) / (out - 1)
                                           : static_cast<float>(in) / out;
    const float s = half ? (i + 0.5f) * scale - 0.5f : i * scale;
    *lo = std::max(static_cast<int>(std::floor(s)), 0);
    *hi = std::min(static_cast<int>(std::ceil(s)), in - 1);
    *frac = s - std::floor(s);
  };
  std::vector<float> y;
  for (int oy = 0; oy < oh; ++oy)
    for (int ox = 0; ox < ow; ++ox)
      for (int ch = 0; ch < c; ++ch) {
        float fy, fx;
        int y0, y1, x0, x1;
        source(oy, h, oh, &fy, &y0, &y1);
        source(ox, w, ow, &fx, &x0, &x1);
        y.push_back(x[Nhwc(y0, x0, ch, w, c)] * (1 - fy) * (1 - fx) +
                    x[Nhwc(y1, x0, ch, w, c)] * fy * (1 - fx) +
                    x[Nhwc(y0, x1, ch, w, c)] * (1 - fy) * fx +
                    x[Nhwc(y1, x1, ch, w, c)] * fy * fx);
      }
  return y;
}

TEST(TfliteOps, ResizeBilinearConventions) {
  std::mt19937 rng(15);
  const int h = 3, w = 4, c = 2;
  const std::vector<float> x = RandomFloats(h * w * c, rng);
  struct Mode {
    bool align, half;
  };
  for (Mode m : {Mode{false, false}, Mode{true, false}, Mode{false, true}}) {
    for (auto [oh, ow] : {std::pair{6, 8}, std::pair{5, 3}}) {
      TfliteBuilder b;
      const int in = b.Tensor({1, h, w, c});
      const int out = b.Tensor({1, oh, ow, c});
      b.Op(kResize, {in, b.ConstantInt({2}, {oh, ow})}, {out},
           fb::BuiltinOptions_ResizeBilinearOptions,
           fb::CreateResizeBilinearOptions(b.fbb(), m.align, m.half).Union());
      ExpectNear(RunOne(b.Finish({in}, {out}), x),
                 ReferenceResize(x, h, w, c, oh, ow, m.align, m.half), 1e-5f);
    }
  }
}

TEST(TfliteOps, ResizeBilinearHandWorkedRow) {
  // One row [0, 10] resized to width 4: legacy s = 0, .5, 1, 1.5 -> 0, 5, 10, 10;
  // half-pixel s = -.25, .25, .75, 1.25 -> 0, 2.5, 7.5, 10; align_corners s = 0, 1/3,
  // 2/3, 1 -> 0, 3.33, 6.67, 10.
  const std::vector<std::vector<float>> want{
      {0, 5, 10, 10}, {0, 2.5, 7.5, 10}, {0, 10 / 3.0f, 20 / 3.0f, 10}};
  for (int mode = 0; mode < 3; ++mode) {
    TfliteBuilder b;
    const int in = b.Tensor({1, 1, 2, 1});
    const int out = b.Tensor({1, 1, 4, 1});
    b.Op(kResize, {in, b.ConstantInt({2}, {1, 4})}, {out},
         fb::BuiltinOptions_ResizeBilinearOptions,
         fb::CreateResizeBilinearOptions(b.fbb(), mode == 2, mode == 1).Union());
    ExpectNear(RunOne(b.Finish({in}, {out}), {0, 10}), want[mode], 1e-5f);
  }
}

TEST(TfliteOps, ReshapeAndConcatenationKeepTfliteOrder) {
  std::mt19937 rng(16);
  const int h = 2, w = 2, c = 3;
  const std::vector<float> x = RandomFloats(h * w * c, rng);
  TfliteBuilder b;
  const int in = b.Tensor({1, h, w, c});
  const int pooled = b.Tensor({1, h, w, c});
  b.Op(kMaxPool, {in}, {pooled}, fb::BuiltinOptions_Pool2DOptions,
       fb::CreatePool2DOptions(b.fbb(), fb::Padding_VALID, 1, 1, 1, 1).Union());
  // Channel concat of two NCHW values, then [1, h*w*2, 3] reshape and concat on axis 1.
  const int both = b.Tensor({1, h, w, 2 * c});
  b.Op(kConcatenation, {pooled, pooled}, {both}, fb::BuiltinOptions_ConcatenationOptions,
       fb::CreateConcatenationOptions(b.fbb(), -1).Union());
  const int rows = b.Tensor({1, h * w * 2, c});
  b.Op(kReshape, {both, b.ConstantInt({3}, {1, h * w * 2, c})}, {rows});
  const int flat_in = b.Tensor({1, h * w, c});
  b.Op(kReshape, {in, b.ConstantInt({3}, {1, h * w, c})}, {flat_in});
  const int out = b.Tensor({1, h * w * 3, c});
  b.Op(kConcatenation, {rows, flat_in}, {out}, fb::BuiltinOptions_ConcatenationOptions,
       fb::CreateConcatenationOptions(b.fbb(), 1).Union());
  std::vector<float> want;
  for (int p = 0; p < h * w; ++p) {
    for (int rep = 0; rep < 2; ++rep)
      for (int ch = 0; ch < c; ++ch) want.push_back(x[p * c + ch]);
  }
  want.insert(want.end(), x.begin(), x.end());
  ExpectNear(RunOne(b.Finish({in}, {out}), x), want, 0);
}

}  // namespace
}  // namespace handlabel
