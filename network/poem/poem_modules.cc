#include "network/poem/poem_modules.h"

#include "network/poem/point_ops.h"

#include <ATen/Parallel.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/errors.h"

namespace handlabel {

namespace F = torch::nn::functional;

FrozenBatchNorm2dImpl::FrozenBatchNorm2dImpl(int64_t channels) {
  weight = register_buffer("weight", torch::ones({channels}));
  bias = register_buffer("bias", torch::zeros({channels}));
  running_mean = register_buffer("running_mean", torch::zeros({channels}));
  running_var = register_buffer("running_var", torch::ones({channels}));
}

torch::Tensor FrozenBatchNorm2dImpl::forward(const torch::Tensor& x) {
  const torch::Tensor w = weight.reshape({1, -1, 1, 1});
  const torch::Tensor b = bias.reshape({1, -1, 1, 1});
  const torch::Tensor rv = running_var.reshape({1, -1, 1, 1});
  const torch::Tensor rm = running_mean.reshape({1, -1, 1, 1});
  const torch::Tensor scale = w * (rv + 1e-5).rsqrt();
  const torch::Tensor shift = b - rm * scale;
  return x * scale + shift;
}

torch::Tensor CastForInference(const torch::Tensor& x, torch::ScalarType type) {
  if (x.scalar_type() == type) return x;
  // empty + copy_ keeps x's memory format and runs ATen's vectorised conversion (on
  // LibTorch 1.13, x.to(kBFloat16) took 20-40x as long for the same copy).
  return at::empty_like(x, x.options().dtype(type)).copy_(x);
}

torch::Tensor FoldedConv::operator()(const torch::Tensor& x) const {
  if (weight.scalar_type() == x.scalar_type()) {
    return at::conv2d(x, weight, bias, stride, padding);
  }
  // Channels-last: oneDNN's bf16 kernels then read and write the activations in place
  // of reordering them to and from its blocked layout on every call.
  const torch::Tensor low = at::empty(x.sizes(), x.options().dtype(weight.scalar_type()),
                                      at::MemoryFormat::ChannelsLast)
                                .copy_(x);
  const torch::Tensor y = at::conv2d(low, weight, bias, stride, padding);
  return CastForInference(y, x.scalar_type());
}

FoldedConv FoldConvNorm(const torch::nn::Conv2dImpl& conv, torch::nn::Module& norm) {
  torch::Tensor gamma, beta, mean, var;
  double eps = 1e-5;
  if (auto* frozen = norm.as<FrozenBatchNorm2d>()) {
    gamma = frozen->weight, beta = frozen->bias;
    mean = frozen->running_mean, var = frozen->running_var;
  } else if (auto* bn = norm.as<torch::nn::BatchNorm2d>()) {
    HL_CHECK(!bn->is_training(), "FoldConvNorm: batch norm in training mode");
    gamma = bn->weight, beta = bn->bias;
    mean = bn->running_mean, var = bn->running_var;
    eps = bn->options.eps();
  } else {
    HL_CHECK(false, "FoldConvNorm: not a batch norm module");
  }
  torch::NoGradGuard no_grad;
  const torch::Tensor scale = gamma * (var + eps).rsqrt();
  const torch::Tensor bias = conv.bias.defined() ? conv.bias : torch::zeros_like(mean);
  FoldedConv f;
  f.weight = (conv.weight * scale.reshape({-1, 1, 1, 1})).contiguous();
  f.bias = (bias - mean) * scale + beta;
  f.stride = c10::IntArrayRef(conv.options.stride()).vec();
  f.padding =
      c10::IntArrayRef(c10::get<torch::ExpandingArray<2>>(conv.options.padding())).vec();
  return f;
}

void ConvertToBf16ForInference(torch::nn::Module& module) {
  torch::NoGradGuard no_grad;
  auto convert = [](FoldedConv& f) {
    if (!f.defined()) return;
    f.weight = f.weight.to(torch::kBFloat16);
    f.bias = f.bias.to(torch::kBFloat16);
  };
  for (const auto& m : module.modules()) {
    if (auto* block = m->as<BasicBlock>()) {
      HL_CHECK(block->folded1.defined(),
               "ConvertToBf16ForInference: fold the norms first");
      convert(block->folded1), convert(block->folded2), convert(block->folded_downsample);
    }
    if (auto* resnet = m->as<ResNet>()) convert(resnet->folded_stem);
    if (auto* conv_block = m->as<ConvBlock>()) convert(conv_block->folded);
    if (auto* linear = m->as<torch::nn::Linear>()) {
      linear->weight.set_data(linear->weight.to(torch::kBFloat16));
      if (linear->bias.defined())
        linear->bias.set_data(linear->bias.to(torch::kBFloat16));
    }
  }
}

void FoldNormsForInference(torch::nn::Module& model) {
  HL_CHECK(!model.is_training(), "FoldNormsForInference: the model is in training mode");
  for (const auto& m : model.modules()) {
    if (auto* block = m->as<BasicBlock>()) block->FoldNorms();
    if (auto* resnet = m->as<ResNet>()) resnet->FoldNorms();
    if (auto* conv_block = m->as<ConvBlock>()) conv_block->FoldNorms();
  }
}

namespace {

torch::nn::AnyModule MakeNorm(int64_t channels, bool frozen) {
  if (frozen) return torch::nn::AnyModule(FrozenBatchNorm2d(channels));
  return torch::nn::AnyModule(torch::nn::BatchNorm2d(channels));
}

torch::nn::Conv2d Conv(int64_t in, int64_t out, int64_t kernel, int64_t stride,
                       int64_t padding, bool bias) {
  return torch::nn::Conv2d(torch::nn::Conv2dOptions(in, out, kernel)
                               .stride(stride)
                               .padding(padding)
                               .bias(bias));
}

void KaimingFanOut(torch::nn::Conv2d& conv) {
  torch::NoGradGuard no_grad;
  torch::nn::init::kaiming_normal_(conv->weight, 0.0, torch::kFanOut, torch::kReLU);
}

}  // namespace

BasicBlockImpl::BasicBlockImpl(int64_t inplanes, int64_t planes, int64_t stride,
                               bool frozen_bn) {
  conv1 = register_module("conv1", Conv(inplanes, planes, 3, stride, 1, false));
  bn1 = MakeNorm(planes, frozen_bn);
  register_module("bn1", bn1.ptr());
  conv2 = register_module("conv2", Conv(planes, planes, 3, 1, 1, false));
  bn2 = MakeNorm(planes, frozen_bn);
  register_module("bn2", bn2.ptr());
  if (stride != 1 || inplanes != planes) {
    torch::nn::Sequential ds;
    ds->push_back(Conv(inplanes, planes, 1, stride, 0, false));
    ds->push_back(MakeNorm(planes, frozen_bn));
    downsample = register_module("downsample", ds);
  }
  KaimingFanOut(conv1);
  KaimingFanOut(conv2);
}

void BasicBlockImpl::FoldNorms() {
  folded1 = FoldConvNorm(*conv1, *bn1.ptr());
  folded2 = FoldConvNorm(*conv2, *bn2.ptr());
  if (downsample) {
    folded_downsample =
        FoldConvNorm(*downsample[0]->as<torch::nn::Conv2d>(), *downsample->ptr(1));
  }
}

torch::Tensor BasicBlockImpl::forward(const torch::Tensor& x) {
  if (folded1.defined() && UseInferenceKernels()) {
    torch::Tensor out = folded2(folded1(x).relu_());
    out += folded_downsample.defined() ? folded_downsample(x) : x;
    return out.relu_();
  }
  torch::Tensor out = torch::relu(bn1.forward(conv1(x)));
  out = bn2.forward(conv2(out));
  const torch::Tensor residual = downsample ? downsample->forward(x) : x;
  return torch::relu(out + residual);
}

ResNetImpl::ResNetImpl(const std::array<int, 4>& blocks, int width) {
  conv1 = register_module("conv1", Conv(3, width, 7, 2, 3, false));
  KaimingFanOut(conv1);
  bn1 = register_module("bn1", FrozenBatchNorm2d(width));
  int64_t inplanes = width;
  for (int s = 0; s < 4; ++s) {
    const int64_t planes = static_cast<int64_t>(width) << s;
    torch::nn::Sequential layer;
    for (int b = 0; b < blocks[s]; ++b) {
      // Only the first block of each stage uses frozen batch norm (reference).
      layer->push_back(BasicBlock(inplanes, planes, b == 0 && s > 0 ? 2 : 1, b == 0));
      inplanes = planes;
    }
    layers[s] = register_module("layer" + std::to_string(s + 1), layer);
  }
  fc = register_module("fc", torch::nn::Linear(8 * width, 1000));
}

void ResNetImpl::FoldNorms() { folded_stem = FoldConvNorm(*conv1, *bn1); }

std::array<torch::Tensor, 4> ResNetImpl::forward(const torch::Tensor& image) {
  torch::Tensor x = folded_stem.defined() && UseInferenceKernels()
                        ? folded_stem(image).relu_()
                        : torch::relu(bn1(conv1(image)));
  x = F::max_pool2d(x, F::MaxPool2dFuncOptions(3).stride(2).padding(1));
  std::array<torch::Tensor, 4> out;
  for (int s = 0; s < 4; ++s) {
    x = layers[s]->forward(x);
    out[s] = x;
  }
  return out;
}

ConvBlockImpl::ConvBlockImpl(int64_t in, int64_t out, int64_t kernel, bool use_norm,
                             bool use_relu)
    : relu(use_relu) {
  conv = register_module("conv", Conv(in, out, kernel, 1, kernel / 2, true));
  KaimingFanOut(conv);
  if (use_norm) norm = register_module("norm", torch::nn::BatchNorm2d(out));
}

void ConvBlockImpl::FoldNorms() {
  if (norm) folded = FoldConvNorm(*conv, *norm);
}

torch::Tensor ConvBlockImpl::forward(const torch::Tensor& x) {
  if (folded.defined() && UseInferenceKernels()) {
    const torch::Tensor y = folded(x);
    return relu ? y.relu_() : y;
  }
  torch::Tensor y = conv(x);
  if (norm) y = norm(y);
  return relu ? torch::relu(y) : y;
}

torch::nn::ModuleList MakeUDecoder(int width) {
  const int c0 = 8 * width, c1 = 4 * width, c2 = 2 * width, c3 = width;
  torch::nn::ModuleList list;
  list->push_back(ConvBlock(c1 + c0, c1, 3, true, true));
  list->push_back(ConvBlock(c2 + c1, c2, 3, true, true));
  list->push_back(ConvBlock(c3 + c2, c3, 3, true, true));
  return list;
}

torch::Tensor UDecode(torch::nn::ModuleList& delayer,
                      const std::array<torch::Tensor, 4>& f) {
  return F::max_pool2d(UDecodeBeforePool(delayer, f),
                       F::MaxPool2dFuncOptions(2).stride(2));
}

torch::Tensor UDecodeBeforePool(torch::nn::ModuleList& delayer,
                                const std::array<torch::Tensor, 4>& f) {
  torch::Tensor x = f[3];
  for (int i = 0; i < 3; ++i) {
    x = F::interpolate(x, F::InterpolateFuncOptions()
                              .scale_factor(std::vector<double>{2.0, 2.0})
                              .mode(torch::kBilinear)
                              .align_corners(false));
    x = torch::cat({x, f[2 - i]}, 1);
    x = delayer[i]->as<ConvBlock>()->forward(x);
  }
  return x;
}

torch::nn::Sequential Mlp(int64_t in, int64_t hidden, int64_t out) {
  return torch::nn::Sequential(torch::nn::Linear(in, hidden), torch::nn::ReLU(),
                               torch::nn::Linear(hidden, out));
}

bool UseInferenceKernels() { return !torch::GradMode::is_enabled(); }

namespace {

void CheckPixelConv(const torch::nn::Conv2dImpl& conv) {
  const auto& o = conv.options;
  HL_CHECK(conv.weight.size(2) == 1 && conv.weight.size(3) == 1 &&
               (*o.stride())[0] == 1 && (*o.stride())[1] == 1 && o.groups() == 1,
           "pixel MLP: only 1x1 convolutions with stride 1 and one group");
}

// x W^T + b in the weights' precision (bf16 after ConvertToBf16ForInference); weight
// (out, in), or (out, in, 1, 1) for a 1x1 convolution.
torch::Tensor LinearInLayerPrecision(const torch::Tensor& weight,
                                     const torch::Tensor& bias, const torch::Tensor& x) {
  const int64_t out = weight.size(0), in = weight.size(1);
  HL_CHECK(x.size(-1) == in, "InferenceLinear: input width differs from the layer's");
  std::vector<int64_t> shape = x.sizes().vec();
  shape.back() = out;
  // One pass: a cast writes contiguous rows whatever x's strides.
  const torch::Tensor flat = x.reshape({-1, in});
  const torch::Tensor rows =
      weight.scalar_type() == x.scalar_type()
          ? flat.contiguous()
          : at::empty(flat.sizes(), flat.options().dtype(weight.scalar_type()))
                .copy_(flat);
  const int64_t m = rows.size(0);
  if (m == 0) return torch::empty(shape, rows.options());
  // Row-major (m, in) is a (1, in, m, 1) image in channels-last layout: no copy, and
  // oneDNN writes the (1, out, m, 1) result channels-last, i.e. row-major (m, out).
  const torch::Tensor image = rows.as_strided({1, in, m, 1}, {m * in, 1, in, in});
  const torch::Tensor y = at::mkldnn_convolution(
      image, weight.view({out, in, 1, 1}),
      bias.defined() ? c10::optional<torch::Tensor>(bias) : c10::nullopt, {0, 0}, {1, 1},
      {1, 1}, 1);
  return y.permute({0, 2, 3, 1}).reshape(shape);
}

}  // namespace

torch::Tensor InferenceLinear(const torch::nn::LinearImpl& layer,
                              const torch::Tensor& x) {
  return CastForInference(LinearInLayerPrecision(layer.weight, layer.bias, x),
                          x.scalar_type());
}

namespace {

// Rows per chunk of the inference kernels (MLPs, attention): their temporaries (a few
// chunk x d floats each) stay in the cache instead of whole tensors in fresh pages.
constexpr int64_t kCacheChunkRows = 2048;

torch::Tensor InferenceMlpRows(torch::nn::SequentialImpl& mlp, const torch::Tensor& x) {
  // Between the layers the activations stay in the layers' precision: with bf16
  // products on attention-sized chunks, casting every hidden activation to fp32 and
  // back cost about as much as the products.
  torch::Tensor y = x;
  for (const auto& child : mlp.children()) {
    if (const auto* linear = child->as<torch::nn::Linear>()) {
      y = LinearInLayerPrecision(linear->weight, linear->bias, y);
    } else if (const auto* conv = child->as<torch::nn::Conv2d>()) {
      CheckPixelConv(*conv);
      y = LinearInLayerPrecision(conv->weight, conv->bias, y);
    } else {
      HL_CHECK(child->as<torch::nn::ReLU>() != nullptr,
               "InferenceMlp: only Linear, 1x1 Conv2d and ReLU modules");
      y = torch::relu_(y);
    }
  }
  return CastForInference(y, x.scalar_type());
}

}  // namespace

torch::Tensor InferenceMlp(torch::nn::SequentialImpl& mlp, const torch::Tensor& x) {
  const int64_t in = x.size(-1), rows = x.numel() / std::max<int64_t>(in, 1);
  // On the 32768 rows of the released model's view merge the bf16 MLP took 55-60 ms in
  // one piece and 20-25 ms in chunks.
  if (rows <= kCacheChunkRows) return InferenceMlpRows(mlp, x);
  const torch::Tensor flat = x.reshape({rows, in});
  std::vector<torch::Tensor> parts;
  for (int64_t r = 0; r < rows; r += kCacheChunkRows) {
    parts.push_back(
        InferenceMlpRows(mlp, flat.narrow(0, r, std::min(kCacheChunkRows, rows - r))));
  }
  std::vector<int64_t> shape = x.sizes().vec();
  shape.back() = parts[0].size(-1);
  return torch::cat(parts).view(shape);
}

torch::Tensor RunMlp(torch::nn::SequentialImpl& mlp, const torch::Tensor& x) {
  return UseInferenceKernels() ? InferenceMlp(mlp, x) : mlp.forward(x);
}

torch::Tensor RunPixelMlp(torch::nn::SequentialImpl& stack, const torch::Tensor& x) {
  if (!UseInferenceKernels()) return stack.forward(x);
  // (N, C, H, W) as (N, H, W, C) rows: a view when x is channels-last.
  return InferenceMlp(stack, x.permute({0, 2, 3, 1})).permute({0, 3, 1, 2});
}

torch::Tensor RunPixelConv(torch::nn::Conv2d& conv, const torch::Tensor& x) {
  if (!UseInferenceKernels()) return conv(x);
  torch::nn::Sequential one(conv);
  return RunPixelMlp(*one, x);
}

void ConvertPixelConvToBf16(torch::nn::Conv2dImpl& conv) {
  torch::NoGradGuard no_grad;
  CheckPixelConv(conv);
  conv.weight.set_data(conv.weight.to(torch::kBFloat16));
  if (conv.bias.defined()) conv.bias.set_data(conv.bias.to(torch::kBFloat16));
}

VectorAttentionImpl::VectorAttentionImpl(int64_t d_points, int64_t d_model_in, bool cross)
    : d_model(d_model_in) {
  fc1 = register_module("fc1", torch::nn::Linear(d_points, d_model));
  fc2 = register_module("fc2", torch::nn::Linear(d_model, d_points));
  fc_delta = register_module("fc_delta", Mlp(3, d_model, d_model));
  fc_gamma = register_module("fc_gamma", Mlp(d_model, d_model, d_model));
  auto nobias = [](int64_t in, int64_t out) {
    return torch::nn::Linear(torch::nn::LinearOptions(in, out).bias(false));
  };
  w_qs = register_module("w_qs", nobias(cross ? d_points : d_model, d_model));
  w_ks = register_module("w_ks", nobias(d_model, d_model));
  w_vs = register_module("w_vs", nobias(d_model, d_model));
}

torch::Tensor VectorAttentionImpl::Attend(const torch::Tensor& q, const torch::Tensor& k,
                                          const torch::Tensor& v,
                                          const torch::Tensor& rel_xyz) {
  const torch::Tensor pos = fc_delta->forward(rel_xyz);              // (B, Q, k, d)
  torch::Tensor attn = fc_gamma->forward(q.unsqueeze(2) - k + pos);  // (B, Q, k, d)
  attn = torch::softmax(attn / std::sqrt(static_cast<double>(d_model)), -2);
  return (attn * (v + pos)).sum(2);  // (B, Q, d)
}

namespace {

// Splits n queries of k rows each into chunks of about kCacheChunkRows rows, the
// chunk count a multiple of the thread count so that the threads get equal shares.
int64_t QueriesPerChunk(int64_t n, int64_t k) {
  const int64_t threads = std::max(1, at::get_num_threads());
  int64_t chunks = std::max<int64_t>(1, (n * k + kCacheChunkRows - 1) / kCacheChunkRows);
  chunks = (chunks + threads - 1) / threads * threads;
  return std::max<int64_t>(1, (n + chunks - 1) / chunks);
}

}  // namespace

torch::Tensor VectorAttentionImpl::AttendChunked(
    const torch::Tensor& q, const torch::Tensor& k, const torch::Tensor& v,
    const torch::Tensor& query_xyz, const torch::Tensor& point_xyz,
    const torch::Tensor& knn, const torch::Tensor& residual) {
  const int64_t B = q.size(0), Q = q.size(1), P = k.size(1), K = knn.size(2);
  const int64_t d = d_model;
  // Everything flattened over the batch; neighbour indices into the flattened points.
  const torch::Tensor qf = q.reshape({B * Q, d}).contiguous();
  const torch::Tensor kf = k.reshape({B * P, d}).contiguous();
  const torch::Tensor vf = v.reshape({B * P, d}).contiguous();
  const torch::Tensor qxyz = query_xyz.reshape({B * Q, 3}).contiguous();
  const torch::Tensor pxyz = point_xyz.reshape({B * P, 3}).contiguous();
  const torch::Tensor offset = torch::arange(B, knn.options()).mul_(P).view({B, 1, 1});
  const torch::Tensor index = (knn + offset).reshape({B * Q, K});
  const double scale = std::sqrt(static_cast<double>(d));
  torch::Tensor agg = torch::empty({B * Q, d}, q.options());
  const int64_t per_chunk = QueriesPerChunk(B * Q, K);
  const int64_t chunks = (B * Q + per_chunk - 1) / per_chunk;
  // One chunk per task; inside a task every ATen and oneDNN call runs single-threaded.
  at::parallel_for(0, chunks, 1, [&](int64_t begin, int64_t end) {
    for (int64_t c = begin; c < end; ++c) {
      const int64_t q0 = c * per_chunk, n = std::min(per_chunk, B * Q - q0);
      const torch::Tensor idx = index.narrow(0, q0, n).reshape({-1});
      // The same element-wise operations, in the same order, as Attend().
      const torch::Tensor rel =
          qxyz.narrow(0, q0, n).unsqueeze(1) - pxyz.index_select(0, idx).view({n, K, 3});
      const torch::Tensor pos = InferenceMlp(*fc_delta, rel);  // (n, K, d)
      const torch::Tensor logits = InferenceMlp(
          *fc_gamma,
          (qf.narrow(0, q0, n).unsqueeze(1) - kf.index_select(0, idx).view({n, K, d}))
              .add_(pos));
      const torch::Tensor attn = torch::softmax(logits.div_(scale), 1);
      const torch::Tensor values = vf.index_select(0, idx).view({n, K, d}).add_(pos);
      torch::Tensor out = agg.narrow(0, q0, n);
      torch::sum_out(out, attn.mul_(values), at::IntArrayRef{1});
    }
  });
  return InferenceLinear(*fc2, agg.view({B, Q, d})) + residual;
}

torch::Tensor VectorAttentionImpl::SelfAttention(const torch::Tensor& xyz,
                                                 const torch::Tensor& features,
                                                 const torch::Tensor& knn) {
  if (UseInferenceKernels()) {
    const torch::Tensor x = InferenceLinear(*fc1, features);
    return AttendChunked(InferenceLinear(*w_qs, x), InferenceLinear(*w_ks, x),
                         InferenceLinear(*w_vs, x), xyz, xyz, knn, features);
  }
  const torch::Tensor x = fc1(features);
  const torch::Tensor q = w_qs(x);
  const torch::Tensor k = GatherNeighbors(w_ks(x), knn);
  const torch::Tensor v = GatherNeighbors(w_vs(x), knn);
  const torch::Tensor rel = xyz.unsqueeze(2) - GatherNeighbors(xyz, knn);
  return fc2(Attend(q, k, v, rel)) + features;
}

torch::Tensor VectorAttentionImpl::CrossAttention(const torch::Tensor& query_xyz,
                                                  const torch::Tensor& query_features,
                                                  const torch::Tensor& point_xyz,
                                                  const torch::Tensor& point_features,
                                                  const torch::Tensor& knn) {
  if (UseInferenceKernels()) {
    const torch::Tensor x = InferenceLinear(*fc1, point_features);
    return AttendChunked(InferenceLinear(*w_qs, query_features),
                         InferenceLinear(*w_ks, x), InferenceLinear(*w_vs, x), query_xyz,
                         point_xyz, knn, query_features);
  }
  const torch::Tensor q = w_qs(query_features);
  // fc1, w_ks and w_vs are linear, so they run on the P points before the gather
  // instead of on the Q*k gathered rows (same result, fewer FLOPs when P < Q*k).
  const torch::Tensor x = fc1(point_features);
  const torch::Tensor k = GatherNeighbors(w_ks(x), knn);
  const torch::Tensor v = GatherNeighbors(w_vs(x), knn);
  const torch::Tensor rel = query_xyz.unsqueeze(2) - GatherNeighbors(point_xyz, knn);
  return fc2(Attend(q, k, v, rel)) + query_features;
}

}  // namespace handlabel
