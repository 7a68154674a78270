#pragma once
// POEM (CVPR 2023) as a LibTorch module: `PoemModel(config)->forward(batch)`.
// Module names follow the reference code, so `named_parameters()` and
// `named_buffers()` give the released checkpoint's keys (docs/network.md).
// Internal to network/ (includes LibTorch); pipeline code uses hand_mesh_predictor.h.

#include <torch/torch.h>

#include <vector>

#include "network/poem/poem_config.h"
#include "network/poem/poem_modules.h"

namespace handlabel {

// One batch of B multi-view frames with N = config.num_views views each.
struct PoemBatch {
  torch::Tensor images;      // (B, N, 3, S, S) float32, RGB / 255 - 0.5 (hand_crop.h)
  torch::Tensor intrinsics;  // (B, N, 3, 3) crop intrinsics (pixels of the S x S crop)
  torch::Tensor master_from_cam;  // (B, N, 4, 4) camera -> master frame, metres; view 0
                                  // is the master (identity)
  // Optional (B, N, 21) or (B, N) non-negative DLT weights (0 = view not used, e.g.
  // hand not visible); undefined = all ones (the reference).
  torch::Tensor view_weights;
  // Optional (B, num_sampled_points) int64 frustum point indices replacing the ball
  // selection (tests and diagnostics only).
  torch::Tensor point_index_override;
};

struct PoemOutputs {
  torch::Tensor heatmaps;             // (B, N, 21, H, W), sigmoid outputs
  torch::Tensor joints_2d;            // (B, N, 21, 2) crop pixels (corner convention)
  torch::Tensor triangulated_joints;  // (B, 21, 3) master frame, metres
  torch::Tensor initial_mesh;         // (B, 799, 3) [21 joints; 778 vertices], metres
  torch::Tensor ball_center;          // (B, 3) metres
  torch::Tensor point_index;          // (B, K) int64 indices into the flattened frustum
  torch::Tensor sampled_points;       // (B, K, 3) metres
  std::vector<int64_t> points_inside_ball;  // per frame: frustum points inside the ball
  torch::Tensor layer_coords;               // (L, B, 799, 3) every decoder layer, metres
  // (B, N, M, M) hand-mask logits, M = config.mask_size(); undefined without a mask
  // head. Pixel (i, j) covers crop pixels [4j, 4j + 4) x [4i, 4i + 4).
  torch::Tensor mask_logits;

  torch::Tensor joints() const;    // (B, 21, 3) last layer
  torch::Tensor vertices() const;  // (B, 778, 3) last layer
};

// Wall time of each forward-pass stage, summed over calls, in order of first
// appearance (bench/poem_bench.cc). Collected only when set on a model.
struct PoemStageTimes {
  std::vector<std::pair<std::string, double>> seconds;
  void Add(const std::string& stage, double s);
};

// The decoder `PtEmbedTRv2` (keys feats_self_attn, query_self_attn.i,
// query_feats_cross_attn.i).
struct PointDecoderImpl : torch::nn::Module {
  explicit PointDecoderImpl(const PoemConfig& config);
  // Normalised coordinates in and out; returns (L, B, 799, 3) normalised.
  torch::Tensor forward(const torch::Tensor& point_xyz, torch::Tensor point_features,
                        torch::Tensor query_xyz, torch::Tensor query_features,
                        torch::nn::ModuleList& reg_branches);
  VectorAttention feats_self_attn{nullptr};
  torch::nn::ModuleList query_self_attn{nullptr}, query_feats_cross_attn{nullptr};
  int point_neighbors, query_neighbors;
  PoemStageTimes* stage_times = nullptr;  // set by PoemModelImpl::forward
};
TORCH_MODULE(PointDecoder);

// `ptEmb_head` (POEM_Projective_SelfAggregation_Head with query type KPT).
struct PoemHeadImpl : torch::nn::Module {
  explicit PoemHeadImpl(const PoemConfig& config);
  // image_features (B, N, C, H, W); mesh (B, 799, 3) metres. Fills the point and
  // decoder fields of `out`.
  void forward(const torch::Tensor& image_features, const torch::Tensor& mesh,
               const PoemBatch& batch, const torch::Tensor& cam_from_master,
               PoemOutputs* out);

  torch::nn::Sequential center_shift_layer{nullptr}, position_encoder{nullptr},
      query_embedding{nullptr};
  torch::nn::Conv2d input_proj{nullptr}, adapt_pos3d{nullptr};
  torch::nn::ModuleList reg_branches{nullptr}, merge_net_feature{nullptr},
      merge_net_query_feature{nullptr};
  torch::nn::Embedding reference_embed{nullptr};
  torch::nn::Linear layer_global_feat{nullptr};  // unused; kept for checkpoint keys
  PointDecoder transformer{nullptr};
  PoemConfig config;
  PoemStageTimes* stage_times = nullptr;  // set by PoemModelImpl::forward
};
TORCH_MODULE(PoemHead);

struct PoemModelImpl : torch::nn::Module {
  explicit PoemModelImpl(const PoemConfig& config);
  // Throws InputError if tensor shapes disagree with the config.
  PoemOutputs forward(const PoemBatch& batch);
  // Mask logits (B, N, M, M) of images (B, N, 3, S, S) with everything but the mask
  // head run without gradients: training the head on frozen features. Needs
  // config.mask_head.
  torch::Tensor MaskLogitsOnFrozenFeatures(const torch::Tensor& images);
  // network.precision: bf16 (docs/speed.md "Reduced precision"): the backbone, the
  // decoders, the view-merge and query MLPs and the transformer's attention compute
  // their products in bf16 (ConvertToBf16ForInference). The geometry (soft-argmax,
  // DLT, inverse skinning, the ball centre and the regression heads) stays fp32.
  // Inference only: call after eval() and FoldNormsForInference.
  void UseBf16ForInference();

  const PoemConfig& config() const { return config_; }
  // Optional: every forward() adds its stage times here (not owned; null = off).
  PoemStageTimes* stage_times = nullptr;

  ResNet img_backbone{nullptr};
  torch::nn::ModuleList uv_delayer{nullptr}, feat_delayer{nullptr};
  ConvBlock uv_out{nullptr}, uv_in{nullptr}, feat_in{nullptr};
  torch::nn::Linear linear_inv_skin{nullptr};
  PoemHead ptEmb_head{nullptr};
  // 3x3 ConvBlock + 1x1 conv on feat_delayer's output before its max-pool; only with
  // config.mask_head (keys mask_head.0.*, mask_head.1.*).
  torch::nn::Sequential mask_head{nullptr};

 private:
  void CheckBatch(const PoemBatch& batch) const;
  PoemConfig config_;
};
TORCH_MODULE(PoemModel);

// A model with deterministic random weights (torch::manual_seed(seed)) and the
// reference's initialisation of linear_inv_skin (1/21, zero bias) and reference_embed
// (uniform [0, 1)).
PoemModel MakeRandomPoemModel(const PoemConfig& config, uint64_t seed);

// Cross-view merge of the reference: f (B, P, N, C) ->
// f[:, :, 0] + mlp_b(sum_{n>=1} e_n <e_n, e_0>), e = mlp_a(f).
torch::Tensor MergeViews(const torch::Tensor& f, torch::nn::ModuleList& merge_net);

}  // namespace handlabel
