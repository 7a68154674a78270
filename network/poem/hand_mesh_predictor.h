#pragma once
// A network that predicts a hand mesh from calibrated multi-view crops, behind an
// abstract, torch-free interface (pipeline code includes only this header). POEM is
// the one implementation today; CreateHandMeshPredictor picks it by name.
//
// Frames are validated when they are passed in (view count, crop size, finite
// cameras) and the model is validated once when it is loaded (config vs weights).
// Inference runs in batches under torch::NoGradGuard with the intra-op thread count
// set from the machine (or the options).

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "geometry/rigid3.h"
#include "hand/keypoints2d.h"
#include "network/poem/poem_config.h"

namespace handlabel {

struct HandMeshViewInput {
  // crop_size x crop_size RGB crop, channels first, normalised (hand_crop.h WarpCrop).
  std::vector<float> pixels;
  Eigen::Matrix3d intrinsics = Eigen::Matrix3d::Identity();  // crop intrinsics
  Rigid3 cam_from_master;  // view 0 is the master: identity
  // Triangulation weight of this view (0 = the hand is not visible in it).
  double weight = 1.0;
};

struct HandMeshInput {
  std::vector<HandMeshViewInput> views;  // exactly num_views(), master first
};

using Keypoints3 = Eigen::Matrix<double, kNumHandKeypoints, 3, Eigen::RowMajor>;

struct HandMeshPrediction {
  Keypoints3 joints;  // master frame, metres, SNAP/OpenPose order (last decoder layer)
  Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor> vertices;  // 778 x 3
  Keypoints3 triangulated_joints;  // from the per-view 2D joints (DLT)
  // Per view, in crop pixels; confidence = the heatmap's peak value (sigmoid, 0..1).
  std::vector<Keypoints2d> joints_2d;
  int64_t points_inside_ball = 0;  // frustum points near the initial mesh
  // Per view, the mask head's hand probability (0..1) on an M x M grid over the crop,
  // M = crop_size / 4: cell (row i, column j) covers crop pixels [4j, 4j + 4) x
  // [4i, 4i + 4). Empty when the network has no mask head.
  std::vector<Eigen::MatrixXf> masks;
};

class HandMeshPredictor {
 public:
  virtual ~HandMeshPredictor() = default;
  virtual std::string name() const = 0;
  virtual int num_views() const = 0;
  virtual int crop_size() const = 0;
  // True when predictions carry per-view masks (a POEM with a mask head).
  virtual bool predicts_masks() const = 0;
  // Learned parameters (weights and biases, not buffers); 0 when unknown.
  virtual int64_t num_parameters() const { return 0; }
  // The arithmetic actually used: "fp32" or "bf16" ("auto" resolved).
  virtual std::string precision() const { return "fp32"; }
  // One prediction per frame. Throws InputError naming the frame, view and field of
  // the first invalid input, before any inference runs. Safe to call from several
  // threads at once (the model is only read); each call uses the intra-op threads.
  virtual std::vector<HandMeshPrediction> Predict(
      const std::vector<HandMeshInput>& frames) = 0;
};

struct HandMeshPredictorOptions {
  std::string model = "poem";  // the only one today
  // Weights: a handlabel POEM checkpoint (config embedded) or, with `config` set to a
  // released-* name, the released PtEmbedMultiviewStereo.pth.tar. Empty: random
  // weights from `config` and `random_seed` (tests and benchmarks only).
  std::string weights;
  // PoemConfigByName name ("released-dexycb", "small", ...); empty for own checkpoints.
  std::string config;
  int num_views = 0;  // for "small" / "tiny"
  // Intra-op threads (process-wide: LibTorch has one setting); 0 = the machine's
  // hardware threads.
  int num_threads = 0;
  int batch_size = 4;        // frames per forward pass
  // Arithmetic of the network's products (docs/speed.md "Reduced precision"): "fp32";
  // "bf16" (bf16 inputs and weights, fp32 accumulation; emulated, slowly, on AVX-512
  // CPUs without a bf16 unit; refused on CPUs without AVX-512); "auto" = bf16 where the
  // CPU has a bf16 unit (AVX512_BF16 or AMX-BF16), else fp32.
  std::string precision = "fp32";
  uint64_t random_seed = 0;  // random weights only
  // Throws InputError naming the field.
  void Check(const std::string& source) const;
};

// True when the CPU computes bf16 products in hardware (AVX512_BF16 or AMX-BF16).
bool CpuHasBf16Unit();
// True when LibTorch's oneDNN can run bf16 products at all (AVX-512 BW/VL/DQ; emulated,
// slower than fp32, without a bf16 unit). precision "bf16" is refused elsewhere.
bool CpuCanRunBf16();
// "fp32" or "bf16" for a precision option ("auto" resolved on this CPU).
std::string ResolvePrecision(const std::string& precision);

// Loads the model and validates it; throws InputError naming the file or option.
std::unique_ptr<HandMeshPredictor> CreateHandMeshPredictor(
    const HandMeshPredictorOptions& options);

// Writes a handlabel POEM checkpoint with random weights (tests and benchmarks).
void WriteRandomPoemCheckpoint(const PoemConfig& config, uint64_t seed,
                               const std::string& path);

}  // namespace handlabel
