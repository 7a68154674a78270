#pragma once
// The building blocks of POEM as LibTorch modules, registered under the names of the
// reference implementation so that state_dict keys and shapes match the released
// checkpoint (docs/network.md). Internal to network/ (includes LibTorch).

#include <torch/torch.h>

#include <array>

namespace handlabel {

// Batch norm with fixed statistics and affine parameters, all buffers (not trained):
// y = x * w / sqrt(var + 1e-5) + (b - mean * w / sqrt(var + 1e-5)).
struct FrozenBatchNorm2dImpl : torch::nn::Module {
  explicit FrozenBatchNorm2dImpl(int64_t channels);
  torch::Tensor forward(const torch::Tensor& x);
  torch::Tensor weight, bias, running_mean, running_var;
};
TORCH_MODULE(FrozenBatchNorm2d);

// A convolution with the batch norm after it folded into its weight and bias
// (w * s, (b - mean) * s + beta with s = gamma / sqrt(var + eps)): one pass over the
// activation instead of three. Inference only; see FoldNormsForInference.
struct FoldedConv {
  torch::Tensor weight, bias;
  std::vector<int64_t> stride, padding;
  bool defined() const { return weight.defined(); }
  torch::Tensor operator()(const torch::Tensor& x) const;
};
// `norm` is a FrozenBatchNorm2d or an eval-mode BatchNorm2d.
FoldedConv FoldConvNorm(const torch::nn::Conv2dImpl& conv, torch::nn::Module& norm);

// Gives every convolution + batch norm pair under `model` (ResNet stem and blocks,
// ConvBlock) its folded copy, which forward() then uses whenever no gradient is
// recorded. Call once after loading the weights, in eval() mode: later changes to the
// weights are not seen (the predictor loads once; training and evaluation inside
// training never fold). Outputs differ from the unfolded path by rounding only.
void FoldNormsForInference(torch::nn::Module& model);

// Reduced precision for inference (network.precision: bf16, docs/speed.md): gives every
// folded convolution and every Linear under `module` bf16 weights. Their products then
// take bf16 inputs (cast on the way in) and accumulate in fp32 inside oneDNN; the
// results are cast back, so every other operation still sees and computes fp32.
// Inference only, after FoldNormsForInference: the autograd path no longer runs on the
// converted Linears.
void ConvertToBf16ForInference(torch::nn::Module& module);
// x as `type`, in x's memory format; x itself when it already has that type.
torch::Tensor CastForInference(const torch::Tensor& x, torch::ScalarType type);

// ResNet basic block; `frozen_bn` selects FrozenBatchNorm2d (first block of a stage in
// the reference) or BatchNorm2d (the others).
struct BasicBlockImpl : torch::nn::Module {
  BasicBlockImpl(int64_t inplanes, int64_t planes, int64_t stride, bool frozen_bn);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Conv2d conv1{nullptr}, conv2{nullptr};
  torch::nn::AnyModule bn1, bn2;
  torch::nn::Sequential downsample{nullptr};
  void FoldNorms();
  FoldedConv folded1, folded2, folded_downsample;  // set by FoldNorms
};
TORCH_MODULE(BasicBlock);

// ResNet18/34 trunk (keys conv1, bn1, layer1..4, fc). forward() returns the outputs of
// layer1..layer4 (strides 4, 8, 16, 32). `fc` exists only for checkpoint keys.
struct ResNetImpl : torch::nn::Module {
  ResNetImpl(const std::array<int, 4>& blocks, int width);
  std::array<torch::Tensor, 4> forward(const torch::Tensor& x);
  torch::nn::Conv2d conv1{nullptr};
  FrozenBatchNorm2d bn1{nullptr};
  std::array<torch::nn::Sequential, 4> layers{nullptr, nullptr, nullptr, nullptr};
  torch::nn::Linear fc{nullptr};
  void FoldNorms();  // the stem's; the blocks fold their own
  FoldedConv folded_stem;
};
TORCH_MODULE(ResNet);

// Conv2d (with bias) + optional BatchNorm2d + optional ReLU (keys conv, norm).
struct ConvBlockImpl : torch::nn::Module {
  ConvBlockImpl(int64_t in, int64_t out, int64_t kernel, bool norm, bool relu);
  torch::Tensor forward(const torch::Tensor& x);
  torch::nn::Conv2d conv{nullptr};
  torch::nn::BatchNorm2d norm{nullptr};
  bool relu;
  void FoldNorms();  // only with a norm
  FoldedConv folded;
};
TORCH_MODULE(ConvBlock);

// Three steps of (bilinear x2, concat skip, 3x3 ConvBlock), then 2x2 max-pool:
// the reference's `uv_delayer` / `feat_delayer` (keys 0, 1, 2).
torch::Tensor UDecode(torch::nn::ModuleList& delayer,
                      const std::array<torch::Tensor, 4>& f);
// The same before the max-pool (the resolution of f[0], crop_size / 4).
torch::Tensor UDecodeBeforePool(torch::nn::ModuleList& delayer,
                                const std::array<torch::Tensor, 4>& f);
torch::nn::ModuleList MakeUDecoder(int width);

// Linear(in, hidden), ReLU, Linear(hidden, out) as a Sequential (keys 0, 2).
torch::nn::Sequential Mlp(int64_t in, int64_t hidden, int64_t out);

// Inference kernels (docs/speed.md). They run when no gradient is recorded
// (NoGradGuard / inference): the same math as the modules' autograd path, evaluated
// with oneDNN instead of the system BLAS (on Debian a serial, generic OpenBLAS kernel)
// and in cache-sized chunks; results differ from the autograd path by rounding only.
bool UseInferenceKernels();
// x (..., in) -> (..., out): layer(x) as a oneDNN 1x1 convolution on channels-last rows.
torch::Tensor InferenceLinear(const torch::nn::LinearImpl& layer, const torch::Tensor& x);
// A Sequential of Linear and ReLU modules (Mlp), each Linear through InferenceLinear.
torch::Tensor InferenceMlp(torch::nn::SequentialImpl& mlp, const torch::Tensor& x);
// mlp(x) through InferenceMlp when UseInferenceKernels(), else the modules' forward.
torch::Tensor RunMlp(torch::nn::SequentialImpl& mlp, const torch::Tensor& x);
// A stack of 1x1 convolutions (Conv2d, stride 1) and ReLUs on (N, C, H, W) maps, or one
// such convolution: for inference an MLP over the pixels in channels-last layout (the
// result is channels-last), so oneDNN does not reorder the maps to its blocked layout
// and back around every layer; else the modules' forward.
torch::Tensor RunPixelMlp(torch::nn::SequentialImpl& stack, const torch::Tensor& x);
torch::Tensor RunPixelConv(torch::nn::Conv2d& conv, const torch::Tensor& x);
// A 1x1 convolution's weights in bf16 for RunPixelMlp / RunPixelConv (inference only).
void ConvertPixelConvToBf16(torch::nn::Conv2dImpl& conv);

// Point Transformer vector attention without heads (keys fc1, fc2, fc_delta, fc_gamma,
// w_qs, w_ks, w_vs). Self-attention: neighbours among the same points. Cross
// attention: queries attend to point features (fc1 applies to the point features, w_qs
// directly to the query features).
struct VectorAttentionImpl : torch::nn::Module {
  VectorAttentionImpl(int64_t d_points, int64_t d_model, bool cross);
  // xyz (B, P, 3), features (B, P, d_points), knn (B, P, k) -> (B, P, d_points).
  torch::Tensor SelfAttention(const torch::Tensor& xyz, const torch::Tensor& features,
                              const torch::Tensor& knn);
  // query_xyz (B, Q, 3), query_features (B, Q, d_points), point_xyz (B, P, 3),
  // point_features (B, P, d_points), knn (B, Q, k) into the points -> (B, Q, d_points).
  torch::Tensor CrossAttention(const torch::Tensor& query_xyz,
                               const torch::Tensor& query_features,
                               const torch::Tensor& point_xyz,
                               const torch::Tensor& point_features,
                               const torch::Tensor& knn);
  torch::nn::Linear fc1{nullptr}, fc2{nullptr}, w_qs{nullptr}, w_ks{nullptr},
      w_vs{nullptr};
  torch::nn::Sequential fc_delta{nullptr}, fc_gamma{nullptr};
  int64_t d_model;

 private:
  torch::Tensor Attend(const torch::Tensor& q, const torch::Tensor& k,
                       const torch::Tensor& v, const torch::Tensor& rel_xyz);
  // The inference kernel of Attend + fc2 + residual, without B x Q x k x d temporaries:
  // q (B, Q, d), k and v (B, P, d) per point (not gathered), xyz as in CrossAttention.
  torch::Tensor AttendChunked(const torch::Tensor& q, const torch::Tensor& k,
                              const torch::Tensor& v, const torch::Tensor& query_xyz,
                              const torch::Tensor& point_xyz, const torch::Tensor& knn,
                              const torch::Tensor& residual);
};
TORCH_MODULE(VectorAttention);

}  // namespace handlabel
