// The POEM implementation of HandMeshPredictor (hand_mesh_predictor.h).

#include <ATen/Parallel.h>

#include <algorithm>
#include <thread>

#include "core/errors.h"
#include "core/option_checks.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_batch.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_import.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"

namespace handlabel {
namespace {

std::string FrameView(size_t f, size_t v) {
  return "frame " + std::to_string(f) + " view " + std::to_string(v);
}

class PoemPredictor : public HandMeshPredictor {
 public:
  PoemPredictor(PoemModel model, int batch_size, const std::string& precision)
      : model_(std::move(model)), batch_size_(batch_size), precision_(precision) {
    model_->eval();
    FoldNormsForInference(*model_);
    if (precision_ == "bf16") model_->UseBf16ForInference();
  }
  std::string precision() const override { return precision_; }

  std::string name() const override { return "poem"; }
  int num_views() const override { return model_->config().num_views; }
  int crop_size() const override { return model_->config().crop_size; }
  bool predicts_masks() const override { return model_->config().mask_head; }
  int64_t num_parameters() const override {
    int64_t count = 0;
    for (const torch::Tensor& p : model_->parameters()) count += p.numel();
    return count;
  }

  std::vector<HandMeshPrediction> Predict(
      const std::vector<HandMeshInput>& frames) override {
    for (size_t f = 0; f < frames.size(); ++f) Validate(frames[f], f);
    std::vector<HandMeshPrediction> out;
    out.reserve(frames.size());
    torch::NoGradGuard no_grad;
    for (size_t begin = 0; begin < frames.size(); begin += batch_size_) {
      const size_t end = std::min(frames.size(), begin + batch_size_);
      RunBatch(frames, begin, end, &out);
    }
    return out;
  }

 private:
  void Validate(const HandMeshInput& frame, size_t f) const {
    const PoemConfig& c = model_->config();
    const size_t pixels = 3 * static_cast<size_t>(c.crop_size) * c.crop_size;
    if (frame.views.size() != static_cast<size_t>(c.num_views)) {
      throw InputError("frame " + std::to_string(f), "views",
                       std::to_string(c.num_views) + " views (the model's view count)",
                       std::to_string(frame.views.size()));
    }
    int weighted = 0;
    for (size_t v = 0; v < frame.views.size(); ++v) {
      const HandMeshViewInput& in = frame.views[v];
      if (in.pixels.size() != pixels) {
        throw InputError(FrameView(f, v), "pixels",
                         "3 x " + std::to_string(c.crop_size) + " x " +
                             std::to_string(c.crop_size) + " floats",
                         std::to_string(in.pixels.size()));
      }
      if (!in.intrinsics.allFinite() || !(in.intrinsics(0, 0) > 0) ||
          !(in.intrinsics(1, 1) > 0)) {
        throw InputError(FrameView(f, v), "intrinsics", "finite, positive focal lengths");
      }
      if (!in.cam_from_master.translation.allFinite() ||
          !in.cam_from_master.rotation.coeffs().allFinite()) {
        throw InputError(FrameView(f, v), "cam_from_master", "a finite transform");
      }
      if (!(in.weight >= 0)) {
        throw InputError(FrameView(f, v), "weight", ">= 0", std::to_string(in.weight));
      }
      weighted += in.weight > 0;
    }
    if (weighted < 2) {
      throw InputError("frame " + std::to_string(f), "views",
                       "at least 2 views with weight > 0 (triangulation)",
                       std::to_string(weighted));
    }
  }

  void RunBatch(const std::vector<HandMeshInput>& frames, size_t begin, size_t end,
                std::vector<HandMeshPrediction>* out) {
    const int64_t B = end - begin, N = model_->config().num_views;
    const PoemBatch batch = MakePoemBatch(frames, begin, end, model_->config());
    const PoemOutputs o = model_->forward(batch);
    const torch::Tensor joints = o.joints().to(torch::kFloat64).contiguous();
    const torch::Tensor verts = o.vertices().to(torch::kFloat64).contiguous();
    const torch::Tensor tri = o.triangulated_joints.to(torch::kFloat64).contiguous();
    const torch::Tensor uv = o.joints_2d.to(torch::kFloat64).contiguous();
    const torch::Tensor peak =
        std::get<0>(o.heatmaps.flatten(3).max(-1)).to(torch::kFloat64).contiguous();
    torch::Tensor masks;
    if (o.mask_logits.defined()) {
      masks = torch::sigmoid(o.mask_logits).to(torch::kFloat32).contiguous();
    }
    for (int64_t b = 0; b < B; ++b) {
      HandMeshPrediction p;
      p.joints = Eigen::Map<const Keypoints3>(joints[b].data_ptr<double>());
      p.vertices =
          Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>>(
              verts[b].data_ptr<double>(), PoemConfig::kNumVertices, 3);
      p.triangulated_joints = Eigen::Map<const Keypoints3>(tri[b].data_ptr<double>());
      for (int64_t n = 0; n < N; ++n) {
        Keypoints2d& view = p.joints_2d.emplace_back();
        view.uv_px = Eigen::Map<const KeypointPixels>(uv[b][n].data_ptr<double>());
        view.confidence =
            Eigen::Map<const KeypointConfidences>(peak[b][n].data_ptr<double>());
        if (masks.defined()) {
          const int64_t M = masks.size(2);
          p.masks.push_back(
              Eigen::Map<const Eigen::Matrix<float, Eigen::Dynamic, Eigen::Dynamic,
                                             Eigen::RowMajor>>(
                  masks[b][n].data_ptr<float>(), M, M));
        }
      }
      p.points_inside_ball = o.points_inside_ball.empty() ? 0 : o.points_inside_ball[b];
      out->push_back(std::move(p));
    }
  }

  PoemModel model_;
  int batch_size_;
  std::string precision_;
};

PoemModel LoadModel(const HandMeshPredictorOptions& o) {
  if (o.weights.empty()) {
    return MakeRandomPoemModel(PoemConfigByName(o.config, o.num_views), o.random_seed);
  }
  if (o.config.rfind("released-", 0) == 0) {
    return ImportReleasedPoemCheckpoint(o.weights,
                                        PoemConfigByName(o.config, o.num_views));
  }
  PoemModel model = LoadPoemCheckpoint(o.weights);
  if (!o.config.empty()) {
    PoemConfig wanted = PoemConfigByName(o.config, o.num_views);
    wanted.mask_head = model->config().mask_head;  // an optional extra, not a size
    const auto diff = wanted.Differences(model->config());
    if (!diff.empty()) {
      std::string got;
      for (const auto& d : diff) got += (got.empty() ? "" : "; ") + d;
      throw InputError(o.weights, "config", "a checkpoint for config '" + o.config + "'",
                       "other sizes (requested vs file: " + got + ")");
    }
  }
  return model;
}

}  // namespace

void HandMeshPredictorOptions::Check(const std::string& source) const {
  if (model != "poem") throw InputError(source, "model", "poem", model);
  if (weights.empty() && config.empty()) {
    throw InputError(source, "config", "a config name when no weights are given",
                     "empty");
  }
  RequireAtLeast(source, "num_threads", num_threads, 0,
                 ">= 0 (0 = all hardware threads)");
  RequireAtLeast(source, "batch_size", batch_size, 1);
  if (precision != "fp32" && precision != "bf16" && precision != "auto") {
    throw InputError(source, "precision", "fp32, bf16 or auto", precision);
  }
}

bool CpuHasBf16Unit() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512bf16") || __builtin_cpu_supports("amx-bf16");
}

bool CpuCanRunBf16() {
  // LibTorch 1.13's oneDNN bf16 convolutions refuse CPUs without these (they emulate
  // the bf16 products with AVX-512 where there is no bf16 unit).
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512vl") &&
         __builtin_cpu_supports("avx512dq");
}

std::string ResolvePrecision(const std::string& precision) {
  if (precision != "auto") return precision;
  return CpuHasBf16Unit() ? "bf16" : "fp32";
}

std::unique_ptr<HandMeshPredictor> CreateHandMeshPredictor(
    const HandMeshPredictorOptions& options) {
  options.Check("hand mesh predictor options");
  const int threads = options.num_threads > 0
                          ? options.num_threads
                          : std::max(1u, std::thread::hardware_concurrency());
  const std::string precision = ResolvePrecision(options.precision);
  if (precision == "bf16" && !CpuCanRunBf16()) {
    throw InputError("hand mesh predictor options", "precision",
                     "fp32 or auto on this CPU (bf16 needs AVX-512 BW/VL/DQ, which it "
                     "lacks)",
                     "bf16");
  }
  at::set_num_threads(threads);
  return std::make_unique<PoemPredictor>(LoadModel(options), options.batch_size,
                                         precision);
}

void WriteRandomPoemCheckpoint(const PoemConfig& config, uint64_t seed,
                               const std::string& path) {
  PoemModel model = MakeRandomPoemModel(config, seed);
  SavePoemCheckpoint(model, path);
}

}  // namespace handlabel
