#pragma once
// Sizes of a POEM network (docs/network.md). Torch-free, so that pipeline code can
// choose and validate a configuration without including LibTorch.
//
// Everything that changes a tensor shape in the checkpoint lives here; a checkpoint is
// only loadable into a model built from an equal configuration (see Differences()).

#include <array>
#include <string>
#include <vector>

namespace handlabel {

// Datasets whose released POEM weights exist; they differ in view count and position
// range only.
enum class PoemDataset { kDexYCB, kOakInk, kHO3D };

struct PoemConfig {
  static constexpr int kNumJoints = 21;     // SNAP/OpenPose order, wrist first
  static constexpr int kNumVertices = 778;  // MANO topology
  static constexpr int kNumQueries = kNumJoints + kNumVertices;

  // "resnet18" or "resnet34" (BasicBlock ResNets; frozen batch norm in the stem and
  // in the first block of every stage, as the reference).
  std::string backbone = "resnet34";
  // Channels of the first stage; the stages have 1, 2, 4, 8 times this. 64 is the
  // standard ResNet; 32 is half width.
  int backbone_width = 64;
  // Views per multi-view frame. Released weights are specific to it (the sine
  // encoding runs along the view axis and views are summed, not averaged).
  int num_views = 8;
  // Side of the square input crop in pixels; a multiple of 32. Heatmaps and image
  // features are crop_size / 8 wide.
  int crop_size = 256;
  // Depth bins of the frustum point grid per feature pixel.
  int depth_bins = 32;
  // Width of image features, point features and queries (divisible by 4).
  int embed_dim = 256;
  // Inner width of the vector attention blocks.
  int transformer_dim = 256;
  // Decoder blocks (query self-attention, query-to-point cross-attention, regression).
  int num_decoder_blocks = 6;
  // Neighbours in point self-attention and in query-to-point cross-attention.
  int point_neighbors = 16;
  // Neighbours in query self-attention.
  int query_neighbors = 16;
  // Frustum points kept inside the ball around the initial mesh.
  int num_sampled_points = 4096;
  // Ball radius in metres.
  double ball_radius = 0.2;
  // xmin, ymin, zmin, xmax, ymax, zmax in metres, master frame. Points are normalised
  // per axis into [0, 1] by this box; the frustum spans depths [zmin, zmax).
  std::array<double, 6> position_range = {-1.2, -1.2, 0.2, 1.2, 1.2, 2.0};
  // Our addition, absent from the released weights: a per-view hand-mask head on the
  // feature decoder (module `mask_head`, logits at crop_size / 4), so the fitting can
  // use predicted silhouettes when a capture has no masks.
  bool mask_head = false;

  int heatmap_size() const { return crop_size / 8; }
  int mask_size() const { return crop_size / 4; }
  // Channels of `feat_in` (the reference's IN_CHANNELS = layer2 channels).
  int image_feature_dim() const { return 2 * backbone_width; }
  int stage_channels(int stage) const { return backbone_width << stage; }  // 0..3
  std::array<int, 4> stage_blocks() const;

  // Throws InputError naming `source` and the first invalid field.
  void Check(const std::string& source) const;

  // Human-readable "field: this vs other" lines for every field that differs.
  std::vector<std::string> Differences(const PoemConfig& other) const;

  // JSON object with every field (embedded in our checkpoints).
  std::string ToJson() const;
  // Missing fields keep their defaults; unknown fields and bad values throw InputError
  // naming `source`.
  static PoemConfig FromJson(const std::string& json, const std::string& source);
};

// The released configuration for a dataset (ResNet34, 256 crops, 6 blocks, ...).
PoemConfig ReleasedPoemConfig(PoemDataset dataset);
// The released architecture for an arbitrary view count (DexYCB position range).
PoemConfig ReleasedPoemConfig(int num_views);

// A CPU-trainable configuration: half-width ResNet18, 128x128 crops, 16 depth bins,
// 64-wide features, 1024 points, 3 decoder blocks, 8 neighbours.
PoemConfig SmallPoemConfig(int num_views);

// The smallest sensible configuration, for tests: 64x64 crops, 16-wide features.
PoemConfig TinyPoemConfig(int num_views);

// "released-dexycb", "released-oakink", "released-ho3d", "small", "tiny"; the view
// count applies to small and tiny. Throws InputError listing the names.
PoemConfig PoemConfigByName(const std::string& name, int num_views);

}  // namespace handlabel
