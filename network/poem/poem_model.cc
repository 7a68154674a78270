#include "network/poem/poem_model.h"

#include <chrono>

#include "core/errors.h"
#include "core/stopwatch.h"
#include "network/poem/poem_geometry.h"
#include "network/poem/point_ops.h"
#include "network/poem/tensor_shape.h"

namespace handlabel {
namespace {

namespace F = torch::nn::functional;
using torch::indexing::Ellipsis;
using torch::indexing::Slice;

void ExpectShape(const torch::Tensor& t, const std::vector<int64_t>& shape,
                 const std::string& field) {
  bool ok = t.defined() && t.dim() == static_cast<int64_t>(shape.size());
  for (size_t i = 0; ok && i < shape.size(); ++i) ok = t.size(i) == shape[i];
  if (!ok) {
    throw InputError("POEM batch", field, "shape " + ShapeString(shape), ShapeString(t));
  }
  if (t.scalar_type() != torch::kFloat32) {
    throw InputError("POEM batch", field, "float32",
                     std::string(toString(t.scalar_type())));
  }
}

// features (B*N, C, H, W), grid (B*N, P, 1, 2) -> (B, N, C, P), bilinear, zeros
// outside.
torch::Tensor SampleFeatures(const torch::Tensor& features, const torch::Tensor& grid,
                             int64_t B, int64_t N) {
  const torch::Tensor s = F::grid_sample(features, grid,
                                         F::GridSampleFuncOptions()
                                             .mode(torch::kBilinear)
                                             .padding_mode(torch::kZeros)
                                             .align_corners(false));
  return s.reshape({B, N, features.size(1), grid.size(1)});
}

// -> (B, P, N, C)
torch::Tensor SampleViews(const torch::Tensor& features, const torch::Tensor& grid,
                          int64_t B, int64_t N) {
  return SampleFeatures(features, grid, B, N).permute({0, 3, 1, 2});
}

// SampleViews(...).sum(2) -> (B, P, C), summed in grid_sample's own layout: the same
// sums, read contiguously rather than through the permuted view.
torch::Tensor SampleViewsSum(const torch::Tensor& features, const torch::Tensor& grid,
                             int64_t B, int64_t N) {
  return SampleFeatures(features, grid, B, N).sum(1).transpose(1, 2);
}

// Features sampled where the points project in every view, (B, P, N, C), and with
// `summed` given its samples summed over the views, (B, P, C'): grid_sample under
// autograd, SampleViewsForMerge (the same values, one pass) for inference.
ViewSamples SamplePoints(const torch::Tensor& features, const torch::Tensor& grid,
                         int64_t B, int64_t N, const torch::Tensor& summed = {}) {
  if (UseInferenceKernels()) return SampleViewsForMerge(features, grid, B, N, summed);
  ViewSamples s;
  s.per_view = SampleViews(features, grid, B, N);
  if (summed.defined()) s.summed_views = SampleViewsSum(summed, grid, B, N);
  return s;
}

// Adds the time since the previous lap to a stage (nothing when times is null).
class StageClock {
 public:
  explicit StageClock(PoemStageTimes* times) : times_(times) {}
  void Lap(const std::string& stage) {
    if (!times_) return;
    times_->Add(stage, SecondsSince(last_));
    last_ = std::chrono::steady_clock::now();
  }

 private:
  PoemStageTimes* times_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace

void PoemStageTimes::Add(const std::string& stage, double s) {
  for (auto& [name, total] : seconds) {
    if (name == stage) {
      total += s;
      return;
    }
  }
  seconds.emplace_back(stage, s);
}

torch::Tensor PoemOutputs::joints() const {
  return layer_coords[-1].index({Slice(), Slice(0, PoemConfig::kNumJoints)});
}
torch::Tensor PoemOutputs::vertices() const {
  return layer_coords[-1].index(
      {Slice(), Slice(PoemConfig::kNumJoints, torch::indexing::None)});
}

torch::Tensor MergeViews(const torch::Tensor& f, torch::nn::ModuleList& merge_net) {
  const torch::Tensor master_raw = f.index({Slice(), Slice(), 0});
  const torch::Tensor e = RunMlp(*merge_net[0]->as<torch::nn::Sequential>(), f);
  const torch::Tensor master = e.index({Slice(), Slice(), 0});
  const torch::Tensor others =
      e.index({Slice(), Slice(), Slice(1, torch::indexing::None)});
  // Per point: s = others . master, agg = others^T s. As products and sums rather than
  // matmul: LibTorch ran them as one tiny matrix product per point (10 ms of 8 views x
  // 4096 points, against 2 ms).
  const torch::Tensor s = (others * master.unsqueeze(2)).sum(-1, true);  // (B, P, N-1, 1)
  const torch::Tensor agg = (others * s).sum(2);                         // (B, P, C)
  return master_raw + RunMlp(*merge_net[1]->as<torch::nn::Sequential>(), agg);
}

PointDecoderImpl::PointDecoderImpl(const PoemConfig& c)
    : point_neighbors(c.point_neighbors), query_neighbors(c.query_neighbors) {
  feats_self_attn = register_module(
      "feats_self_attn", VectorAttention(c.embed_dim, c.transformer_dim, false));
  query_self_attn = register_module("query_self_attn", torch::nn::ModuleList());
  query_feats_cross_attn =
      register_module("query_feats_cross_attn", torch::nn::ModuleList());
  for (int i = 0; i < c.num_decoder_blocks; ++i) {
    query_self_attn->push_back(VectorAttention(c.embed_dim, c.transformer_dim, false));
    query_feats_cross_attn->push_back(
        VectorAttention(c.embed_dim, c.transformer_dim, true));
  }
}

torch::Tensor PointDecoderImpl::forward(const torch::Tensor& point_xyz,
                                        torch::Tensor point_features,
                                        torch::Tensor query_xyz,
                                        torch::Tensor query_features,
                                        torch::nn::ModuleList& reg_branches) {
  StageClock clock(stage_times);
  const torch::Tensor point_knn = KnnIndices(point_xyz, point_xyz, point_neighbors);
  clock.Lap("kNN points");
  point_features = feats_self_attn->SelfAttention(point_xyz, point_features, point_knn);
  clock.Lap("point self-attention");
  std::vector<torch::Tensor> layers;
  for (size_t i = 0; i < query_self_attn->size(); ++i) {
    const std::string block = "block " + std::to_string(i) + " ";
    const torch::Tensor query_knn = KnnIndices(query_xyz, query_xyz, query_neighbors);
    clock.Lap(block + "kNN queries");
    query_features = query_self_attn[i]->as<VectorAttention>()->SelfAttention(
        query_xyz, query_features, query_knn);
    clock.Lap(block + "query self-attention");
    const torch::Tensor cross_knn = KnnIndices(query_xyz, point_xyz, point_neighbors);
    clock.Lap(block + "kNN query-point");
    query_features = query_feats_cross_attn[i]->as<VectorAttention>()->CrossAttention(
        query_xyz, query_features, point_xyz, point_features, cross_knn);
    clock.Lap(block + "cross-attention");
    const torch::Tensor delta =
        RunMlp(*reg_branches[i]->as<torch::nn::Sequential>(), query_features);
    query_xyz = torch::sigmoid(delta + InverseSigmoid(query_xyz));
    layers.push_back(query_xyz);
    clock.Lap(block + "regression");
  }
  return torch::stack(layers);
}

PoemHeadImpl::PoemHeadImpl(const PoemConfig& c) : config(c) {
  const int64_t E = c.embed_dim, Q = PoemConfig::kNumQueries;
  center_shift_layer = register_module("center_shift_layer", Mlp(Q, Q, 1));
  input_proj = register_module("input_proj", torch::nn::Conv2d(torch::nn::Conv2dOptions(
                                                 c.image_feature_dim(), E, 1)));
  reg_branches = register_module("reg_branches", torch::nn::ModuleList());
  for (int i = 0; i < c.num_decoder_blocks; ++i) reg_branches->push_back(Mlp(E, E, 3));
  adapt_pos3d = register_module(
      "adapt_pos3d", torch::nn::Conv2d(torch::nn::Conv2dOptions(3 * E / 2, E, 1)));
  position_encoder = register_module(
      "position_encoder",
      torch::nn::Sequential(
          torch::nn::Conv2d(torch::nn::Conv2dOptions(3 * c.depth_bins, 2 * E, 1)),
          torch::nn::ReLU(), torch::nn::Conv2d(torch::nn::Conv2dOptions(2 * E, E, 1))));
  reference_embed = register_module("reference_embed", torch::nn::Embedding(Q, E));
  query_embedding = register_module("query_embedding", Mlp(E, E, E));
  auto merge = [&]() {
    torch::nn::ModuleList m;
    m->push_back(Mlp(E, E, E / 2));
    m->push_back(Mlp(E / 2, E / 2, E));
    return m;
  };
  merge_net_feature = register_module("merge_net_feature", merge());
  merge_net_query_feature = register_module("merge_net_query_feature", merge());
  layer_global_feat =
      register_module("layer_global_feat", torch::nn::Linear(c.stage_channels(3), E));
  transformer = register_module("transformer", PointDecoder(c));
}

void PoemHeadImpl::forward(const torch::Tensor& image_features, const torch::Tensor& mesh,
                           const PoemBatch& batch, const torch::Tensor& cam_from_master,
                           PoemOutputs* out) {
  const PoemConfig& c = config;
  const int64_t B = image_features.size(0), N = image_features.size(1);
  const int64_t Hf = image_features.size(3), E = c.embed_dim;
  const double zmin = c.position_range[2], zmax = c.position_range[5];
  StageClock clock(stage_times);

  // Image features with the frustum-coordinate and sine position embeddings.
  torch::Tensor x = RunPixelConv(input_proj, image_features.flatten(0, 1));  // (BN,E,H,W)
  const torch::Tensor frustum = FrustumPoints(batch.intrinsics, batch.master_from_cam, Hf,
                                              c.depth_bins, c.crop_size, zmin, zmax);
  torch::Tensor coords = NormalizePositions(frustum, c.position_range);  // (B,N,W,H,D,3)
  coords = coords.permute({0, 1, 4, 5, 3, 2}).reshape({B * N, 3 * c.depth_bins, Hf, Hf});
  const torch::Tensor coords_embed =
      RunPixelMlp(*position_encoder, InverseSigmoid(coords));
  const torch::Tensor sine = SineEncoding3d(N, Hf, Hf, E / 2).to(x.device());
  const torch::Tensor sin_embed =
      RunPixelConv(adapt_pos3d, sine).repeat({B, 1, 1, 1});  // (BN, E, H, W)
  const torch::Tensor pos_embed = sin_embed + coords_embed;
  x = x + pos_embed;
  // Sampled twice below (queries, points): laid out once as the sampling kernel reads it.
  if (UseInferenceKernels()) x = x.contiguous(at::MemoryFormat::ChannelsLast);
  clock.Lap("frustum points + embeddings");

  // Ball centre: mesh mean shifted by a learnt function of the whole mesh.
  const torch::Tensor shift =
      RunMlp(*center_shift_layer, mesh.transpose(1, 2)).transpose(1, 2);  // (B, 1, 3)
  const torch::Tensor center = mesh.mean(1, /*keepdim=*/true) + 0.01 * shift;
  out->ball_center = center.squeeze(1);

  // Queries: learnt per-vertex embedding + features sampled where the mesh projects.
  const torch::Tensor query_embeds =
      RunMlp(*query_embedding, reference_embed->weight).unsqueeze(0).expand({B, -1, -1});
  const torch::Tensor mesh_grid =
      ProjectToGrid(mesh, batch.intrinsics, cam_from_master, c.crop_size);
  const torch::Tensor query_feat =
      MergeViews(SamplePoints(x, mesh_grid, B, N).per_view, merge_net_query_feature);
  clock.Lap("queries: sampling + merge");

  // Deterministic point selection inside the ball (point_ops.h).
  const torch::Tensor frustum_flat = frustum.reshape({B, -1, 3});
  torch::Tensor index = batch.point_index_override;
  if (!index.defined()) {
    index = SelectBallPoints(frustum_flat, out->ball_center, c.ball_radius,
                             c.num_sampled_points, &out->points_inside_ball);
  }
  out->point_index = index;
  clock.Lap("point selection");
  const torch::Tensor points =
      GatherNeighbors(frustum_flat, index.unsqueeze(-1)).squeeze(2);  // (B, K, 3)
  out->sampled_points = points;
  const torch::Tensor point_grid =
      ProjectToGrid(points, batch.intrinsics, cam_from_master, c.crop_size);
  const ViewSamples point_samples = SamplePoints(x, point_grid, B, N, pos_embed);
  const torch::Tensor point_feat = MergeViews(point_samples.per_view, merge_net_feature);
  const torch::Tensor& point_embed = point_samples.summed_views;
  clock.Lap("points: sampling + merge");

  const torch::Tensor coords_out = transformer->forward(
      NormalizePositions(points, c.position_range), point_feat + point_embed,
      NormalizePositions(mesh, c.position_range), query_feat + query_embeds,
      reg_branches);
  clock = StageClock(stage_times);
  out->layer_coords =
      DenormalizePositions(torch::nan_to_num(coords_out), c.position_range);
  clock.Lap("outputs");
}

PoemModelImpl::PoemModelImpl(const PoemConfig& config) : config_(config) {
  config_.Check("POEM config");
  const int w = config_.backbone_width;
  img_backbone = register_module("img_backbone", ResNet(config_.stage_blocks(), w));
  uv_delayer = register_module("uv_delayer", MakeUDecoder(w));
  uv_out =
      register_module("uv_out", ConvBlock(w, PoemConfig::kNumJoints, 1, false, false));
  uv_in =
      register_module("uv_in", ConvBlock(PoemConfig::kNumJoints, 2 * w, 1, true, true));
  feat_delayer = register_module("feat_delayer", MakeUDecoder(w));
  feat_in = register_module("feat_in", ConvBlock(w, 2 * w, 1, false, false));
  linear_inv_skin = register_module(
      "linear_inv_skin",
      torch::nn::Linear(PoemConfig::kNumJoints, PoemConfig::kNumVertices));
  ptEmb_head = register_module("ptEmb_head", PoemHead(config_));
  {
    torch::NoGradGuard no_grad;
    linear_inv_skin->weight.fill_(1.0 / PoemConfig::kNumJoints);
    linear_inv_skin->bias.zero_();
    ptEmb_head->reference_embed->weight.uniform_(0, 1);
  }
  // Last, so the other modules get the same random weights with or without it.
  if (config_.mask_head) {
    mask_head = register_module("mask_head",
                                torch::nn::Sequential(ConvBlock(w, w, 3, true, true),
                                                      ConvBlock(w, 1, 1, false, false)));
  }
}

void PoemModelImpl::CheckBatch(const PoemBatch& b) const {
  if (!b.images.defined() || b.images.dim() != 5) {
    throw InputError("POEM batch", "images", "(B, N, 3, S, S)", ShapeString(b.images));
  }
  const int64_t B = b.images.size(0), N = config_.num_views, S = config_.crop_size;
  ExpectShape(b.images, {B, N, 3, S, S}, "images");
  ExpectShape(b.intrinsics, {B, N, 3, 3}, "intrinsics");
  ExpectShape(b.master_from_cam, {B, N, 4, 4}, "master_from_cam");
  if (b.view_weights.defined()) {
    const bool per_joint = b.view_weights.dim() == 3;
    ExpectShape(b.view_weights,
                per_joint ? std::vector<int64_t>{B, N, PoemConfig::kNumJoints}
                          : std::vector<int64_t>{B, N},
                "view_weights");
  }
  if (b.point_index_override.defined()) {
    HL_CHECK(b.point_index_override.dim() == 2 && b.point_index_override.size(0) == B &&
                 b.point_index_override.size(1) == config_.num_sampled_points &&
                 b.point_index_override.scalar_type() == torch::kInt64,
             "point_index_override must be (B, num_sampled_points) int64");
  }
}

PoemOutputs PoemModelImpl::forward(const PoemBatch& batch) {
  CheckBatch(batch);
  const PoemConfig& c = config_;
  const int64_t B = batch.images.size(0), N = c.num_views, J = PoemConfig::kNumJoints;
  const int64_t S = c.crop_size, H = c.heatmap_size();
  PoemOutputs out;
  // Written only when it changes: concurrent forward passes (the label job's
  // network batches) then only read the model.
  if (ptEmb_head->stage_times != stage_times) {
    ptEmb_head->stage_times = stage_times;
    ptEmb_head->transformer->stage_times = stage_times;
  }
  StageClock clock(stage_times);

  const auto f = img_backbone->forward(batch.images.reshape({B * N, 3, S, S}));
  clock.Lap("backbone");
  const torch::Tensor feat_full = UDecodeBeforePool(feat_delayer, f);  // (BN, w, 2H, 2W)
  // Contiguous: bf16 inference leaves the decoders' outputs channels-last, and the
  // head's sampling reads them faster in the plain layout.
  const torch::Tensor feat =
      feat_in(F::max_pool2d(feat_full, F::MaxPool2dFuncOptions(2).stride(2)))
          .contiguous();
  if (mask_head) {
    const int64_t M = c.mask_size();
    out.mask_logits = mask_head->forward(feat_full).view({B, N, M, M});
  }
  clock.Lap("feature decoder");
  const torch::Tensor heatmaps = torch::sigmoid(uv_out(UDecode(uv_delayer, f)));
  out.heatmaps = heatmaps.view({B, N, J, H, H});
  clock.Lap("heatmap decoder");
  out.joints_2d = SoftArgmax2d(heatmaps, S).view({B, N, J, 2});

  const torch::Tensor cam_from_master = torch::linalg_inv(batch.master_from_cam);
  torch::Tensor weights = batch.view_weights;
  if (weights.defined() && weights.dim() == 2) {
    weights = weights.unsqueeze(-1).expand({B, N, J});
  }
  out.triangulated_joints =
      TriangulateDlt(out.joints_2d, batch.intrinsics, cam_from_master, weights);

  // Initial mesh: linear inverse skinning of the wrist-relative joints.
  const torch::Tensor root = out.triangulated_joints.index({Slice(), Slice(0, 1)});
  const torch::Tensor rel = out.triangulated_joints - root;
  const torch::Tensor verts = linear_inv_skin(rel.transpose(1, 2)).transpose(1, 2) + root;
  out.initial_mesh = torch::cat({out.triangulated_joints, verts}, 1);
  clock.Lap("soft-argmax + DLT + initial mesh");

  ptEmb_head->forward(feat.view({B, N, feat.size(1), H, H}), out.initial_mesh, batch,
                      cam_from_master, &out);
  return out;
}

torch::Tensor PoemModelImpl::MaskLogitsOnFrozenFeatures(const torch::Tensor& images) {
  HL_CHECK(mask_head, "MaskLogitsOnFrozenFeatures needs a model with a mask head");
  const PoemConfig& c = config_;
  const int64_t B = images.size(0), N = c.num_views, S = c.crop_size, M = c.mask_size();
  HL_CHECK(images.dim() == 5 && images.size(1) == N && images.size(3) == S,
           "images must be (B, num_views, 3, crop_size, crop_size)");
  torch::Tensor features;
  {
    torch::NoGradGuard no_grad;
    features = UDecodeBeforePool(feat_delayer,
                                 img_backbone->forward(images.reshape({B * N, 3, S, S})));
  }
  return mask_head->forward(features).view({B, N, M, M});
}

void PoemModelImpl::UseBf16ForInference() {
  ConvertToBf16ForInference(*img_backbone);
  ConvertToBf16ForInference(*uv_delayer);
  ConvertToBf16ForInference(*feat_delayer);
  if (mask_head) ConvertToBf16ForInference(*mask_head);
  PoemHeadImpl& head = *ptEmb_head;
  ConvertToBf16ForInference(*head.merge_net_feature);
  ConvertToBf16ForInference(*head.merge_net_query_feature);
  ConvertToBf16ForInference(*head.query_embedding);
  ConvertToBf16ForInference(*head.transformer);
  ConvertPixelConvToBf16(*head.input_proj);
  ConvertPixelConvToBf16(*head.adapt_pos3d);
  for (const auto& m : head.position_encoder->modules(/*include_self=*/false)) {
    if (auto* conv = m->as<torch::nn::Conv2d>()) ConvertPixelConvToBf16(*conv);
  }
}

PoemModel MakeRandomPoemModel(const PoemConfig& config, uint64_t seed) {
  torch::manual_seed(seed);
  return PoemModel(config);
}

}  // namespace handlabel
