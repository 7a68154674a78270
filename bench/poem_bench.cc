// CPU cost of a POEM forward pass per multi-view frame (docs/speed.md).
//
//   ./build/bench/poem_bench [--benchmark_filter=Released]
//
// - BM_Gemm: the machine's fp32 GEMM rate in this run, n x n x n through at::matmul
//   (the system BLAS) and through InferenceLinear (oneDNN, the path the network's
//   linear layers take at inference). Arguments: n, threads. Counter GFLOP_per_s.
// - BM_Poem: frames per second through the torch-free HandMeshPredictor (random
//   weights: timings do not depend on the values). Arguments: views, frames per
//   batch, intra-op threads. Counter frames_per_s. The same benchmark exists at
//   a7df249, so old and new builds can be compared name for name.
// - BM_PoemStages: one forward pass of the model split into its stages (backbone,
//   decoders, frustum points, point selection and sampling, kNN, every attention
//   block), each with its counted FLOPs (multiply-adds of the convolutions and linear
//   layers x 2; 8 per kNN distance) and achieved GFLOP/s; printed as a table on
//   stderr. Arguments: views, threads.
// Configs: the released architecture (ResNet34, 256 crops, 4096 points, 6 blocks),
// "small", and the shipped models/poem_small_dexycb.pt (its own config).

#include <ATen/Parallel.h>
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <map>
#include <random>

#include "geometry/rigid3.h"
#include "network/poem/hand_mesh_predictor.h"
#include "network/poem/poem_batch.h"
#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_modules.h"
#include "pipeline/build_config.h"

namespace handlabel {
namespace {

// Cameras on a ring 0.6 m around a hand-sized region 0.6 m in front of the master.
std::vector<HandMeshInput> SyntheticFrames(int frames, int views, int crop) {
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> pixel(-0.5f, 0.5f);
  std::vector<HandMeshInput> out(frames);
  const Eigen::Vector3d center(0, 0, 0.6);
  for (auto& frame : out) {
    for (int n = 0; n < views; ++n) {
      HandMeshViewInput v;
      v.pixels.resize(3 * static_cast<size_t>(crop) * crop);
      for (float& p : v.pixels) p = pixel(rng);
      if (n > 0) {
        const double a = 2 * M_PI * n / views;
        const Eigen::Vector3d eye =
            center +
            0.6 * Eigen::Vector3d(std::sin(a), 0.3 * std::cos(3 * a), -std::cos(a));
        v.cam_from_master = LookAt(eye, center, Eigen::Vector3d(0, -1, 0));
      }
      v.intrinsics << 2.0 * crop, 0, crop / 2.0, 0, 2.0 * crop, crop / 2.0, 0, 0, 1;
      frame.views.push_back(v);
    }
  }
  return out;
}

std::string Shipped(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/" + name;
}

bool IsFile(const std::string& config) { return config.find(".pt") != std::string::npos; }

// ---- GEMM rate -------------------------------------------------------------------

void BM_Gemm(benchmark::State& state, bool onednn) {
  const int64_t n = state.range(0);
  at::set_num_threads(static_cast<int>(state.range(1)));
  torch::manual_seed(1);
  const torch::Tensor a = torch::randn({n, n});
  torch::nn::Linear layer(torch::nn::LinearOptions(n, n).bias(false));
  torch::NoGradGuard no_grad;
  const torch::Tensor b = layer->weight.t();
  for (auto _ : state) {
    benchmark::DoNotOptimize(onednn ? InferenceLinear(*layer, a) : torch::matmul(a, b));
  }
  state.counters["GFLOP_per_s"] = benchmark::Counter(
      2.0 * n * n * n * 1e-9 * state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_Gemm, matmul, false)
    ->Args({2048, 1})
    ->Args({2048, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Gemm, onednn, true)
    ->Args({2048, 1})
    ->Args({2048, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ---- End to end through the predictor ---------------------------------------------

void BM_Poem(benchmark::State& state, const std::string& config) {
  HandMeshPredictorOptions o;
  if (IsFile(config)) {
    o.weights = Shipped(config);
  } else {
    o.config = config;
  }
  o.num_views = static_cast<int>(state.range(0));
  o.batch_size = static_cast<int>(state.range(1));
  o.num_threads = static_cast<int>(state.range(2));
  o.precision = state.range(3) ? "bf16" : "fp32";
  auto predictor = CreateHandMeshPredictor(o);
  const auto frames =
      SyntheticFrames(o.batch_size, predictor->num_views(), predictor->crop_size());
  // Warm-up: oneDNN generates its kernels and the allocator grows its heap on the first
  // call (for the released model's two timed iterations that first call was 10-20 %).
  predictor->Predict(frames);
  for (auto _ : state) benchmark::DoNotOptimize(predictor->Predict(frames));
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * o.batch_size,
                         benchmark::Counter::kIsRate);
}

// Arguments: views, frames per pass, threads, precision (0 = fp32, 1 = bf16).
BENCHMARK_CAPTURE(BM_Poem, Small, std::string("small"))
    ->Args({4, 1, 1, 0})
    ->Args({4, 4, 1, 0})
    ->Args({4, 1, 2, 0})
    ->Args({4, 4, 2, 0})
    ->Args({8, 1, 2, 0})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Poem, Shipped, std::string("models/poem_small_dexycb.pt"))
    ->Args({8, 1, 1, 0})
    ->Args({8, 1, 1, 1})
    ->Args({8, 1, 2, 0})
    ->Args({8, 1, 2, 1})
    ->Args({8, 4, 2, 0})
    ->Args({8, 4, 2, 1})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The released 8-view model takes seconds per frame: a few iterations only.
BENCHMARK_CAPTURE(BM_Poem, Released, std::string("released-dexycb"))
    ->Args({8, 1, 1, 0})
    ->Args({8, 1, 1, 1})
    ->Args({8, 1, 2, 0})
    ->Args({8, 1, 2, 1})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ---- Stage profile -----------------------------------------------------------------

double Conv(int64_t in, int64_t out, int64_t kernel, int64_t side) {
  return 2.0 * in * out * kernel * kernel * side * side;
}
double Linear(int64_t rows, int64_t in, int64_t out) { return 2.0 * rows * in * out; }
double TwoLayers(int64_t rows, int64_t in, int64_t hidden, int64_t out) {
  return Linear(rows, in, hidden) + Linear(rows, hidden, out);
}

// Vector attention: per-point projections, then the MLPs on every (query, neighbour).
double Attention(int64_t queries, int64_t points, int64_t k, int64_t dp, int64_t d,
                 bool cross) {
  const double projections =
      cross ? Linear(queries, dp, d) + Linear(points, dp, d) + 2 * Linear(points, d, d)
            : Linear(points, dp, d) + 3 * Linear(points, d, d);
  return projections + TwoLayers(queries * k, 3, d, d) + TwoLayers(queries * k, d, d, d) +
         Linear(queries, d, dp);
}

// Counted FLOPs of every stage named by the model's StageClock laps, for B frames.
std::map<std::string, double> StageFlops(const PoemConfig& c, int64_t B) {
  const int64_t N = c.num_views, S = c.crop_size, w = c.backbone_width, E = c.embed_dim;
  const int64_t d = c.transformer_dim, H = c.heatmap_size(), D = c.depth_bins;
  const int64_t Q = PoemConfig::kNumQueries, P = c.num_sampled_points;
  std::map<std::string, double> f;
  // Backbone per image: stem, then BasicBlocks (3x3, 3x3, 1x1 downsample).
  double backbone = Conv(3, w, 7, S / 2);
  const auto blocks = c.stage_blocks();
  for (int s = 0; s < 4; ++s) {
    const int64_t planes = w << s, side = S / 4 >> s;
    const int64_t in = s == 0 ? w : planes / 2;
    backbone += Conv(in, planes, 3, side) + Conv(planes, planes, 3, side);
    if (s > 0) backbone += Conv(in, planes, 1, side);
    backbone += (blocks[s] - 1) * 2 * Conv(planes, planes, 3, side);
  }
  const double udecoder = Conv(12 * w, 4 * w, 3, S / 16) + Conv(6 * w, 2 * w, 3, S / 8) +
                          Conv(3 * w, w, 3, S / 4);
  f["backbone"] = B * N * backbone;
  f["feature decoder"] = B * N * (udecoder + Conv(w, 2 * w, 1, H));
  if (c.mask_head)
    f["feature decoder"] += B * N * (Conv(w, w, 3, S / 4) + Conv(w, 1, 1, S / 4));
  f["heatmap decoder"] = B * N * (udecoder + Conv(w, PoemConfig::kNumJoints, 1, H));
  f["soft-argmax + DLT + initial mesh"] =
      B * 3 * Linear(1, PoemConfig::kNumJoints, PoemConfig::kNumVertices);
  f["frustum points + embeddings"] =
      B * N * (Conv(2 * w, E, 1, H) + Conv(3 * D, 2 * E, 1, H) + Conv(2 * E, E, 1, H)) +
      N * Conv(3 * E / 2, E, 1, H);
  auto merge = [&](int64_t rows) {
    return TwoLayers(rows * N, E, E, E / 2) + TwoLayers(rows, E / 2, E / 2, E);
  };
  f["queries: sampling + merge"] =
      B * 3 * TwoLayers(1, Q, Q, 1) + TwoLayers(Q, E, E, E) + B * merge(Q);
  f["points: sampling + merge"] = B * merge(P);
  f["kNN points"] = 8.0 * B * P * P;
  f["point self-attention"] = B * Attention(P, P, c.point_neighbors, E, d, false);
  for (int i = 0; i < c.num_decoder_blocks; ++i) {
    const std::string block = "block " + std::to_string(i) + " ";
    f[block + "kNN queries"] = 8.0 * B * Q * Q;
    f[block + "query self-attention"] =
        B * Attention(Q, Q, c.query_neighbors, E, d, false);
    f[block + "kNN query-point"] = 8.0 * B * Q * P;
    f[block + "cross-attention"] = B * Attention(Q, P, c.point_neighbors, E, d, true);
    f[block + "regression"] = B * TwoLayers(Q, E, E, 3);
  }
  return f;
}

// The model as the predictor prepares it.
PoemModel InferenceModel(const std::string& config, int views, bool bf16) {
  PoemModel model = IsFile(config)
                        ? LoadPoemCheckpoint(Shipped(config))
                        : MakeRandomPoemModel(PoemConfigByName(config, views), 1);
  model->eval();
  FoldNormsForInference(*model);
  if (bf16) model->UseBf16ForInference();
  return model;
}

// The frame through the reference path: for fp32 the autograd path (plain ATen, the
// code before the inference kernels), for bf16 the fp32 inference kernels.
torch::Tensor ReferenceCoords(PoemModel& model, const std::string& config, bool bf16,
                              const PoemBatch& batch) {
  if (bf16) {
    torch::NoGradGuard no_grad;
    PoemModel fp32 = InferenceModel(config, model->config().num_views, false);
    return fp32->forward(batch).layer_coords;
  }
  torch::AutoGradMode with_grad(true);
  return model->forward(batch).layer_coords.detach();
}

void BM_PoemStages(benchmark::State& state, const std::string& config) {
  const int views = static_cast<int>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  const bool bf16 = state.range(2) != 0;
  at::set_num_threads(threads);
  PoemModel model = InferenceModel(config, views, bf16);
  const PoemConfig& c = model->config();
  const PoemBatch batch =
      MakePoemBatch(SyntheticFrames(1, c.num_views, c.crop_size), 0, 1, c);
  torch::NoGradGuard no_grad;
  model->forward(batch);  // warm-up: oneDNN kernels are generated on first use
  PoemStageTimes times;
  model->stage_times = &times;
  double total = 0;
  const std::clock_t cpu_start = std::clock();
  PoemOutputs fast;
  for (auto _ : state) {
    const auto start = std::chrono::steady_clock::now();
    fast = model->forward(batch);
    total +=
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  // Process CPU time (all threads): on a shared machine the wall time includes waiting.
  const double cpu = static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  model->stage_times = nullptr;
  // Exactness: the same frame through the reference path, largest coordinate
  // difference over all decoder layers. Rounding scale: the reference on images scaled
  // by 1 + 1e-6 (a few ulps). The ball query and kNN selections make the outputs jump
  // where a point crosses a boundary, so a pure rounding change can move them this much.
  PoemBatch nudged = batch;
  nudged.images = batch.images * (1 + 1e-6);
  const torch::Tensor reference = ReferenceCoords(model, config, bf16, batch);
  const torch::Tensor nudged_reference = ReferenceCoords(model, config, bf16, nudged);
  const double nudge_diff = (nudged_reference - reference).abs().max().item<double>();
  const torch::Tensor diff = (fast.layer_coords - reference).abs();
  const double max_diff = diff.max().item<double>();
  const double final_diff = diff[-1].max().item<double>();
  const double final_mean = diff[-1].norm(2, -1).mean().item<double>();
  const double n = static_cast<double>(state.iterations());
  const auto flops = StageFlops(c, 1);
  double frame_flops = 0;
  for (const auto& [stage, f] : flops) frame_flops += f;
  std::fprintf(
      stderr,
      "\n%s, %d views, %d thread(s): %.1f ms per frame, %.1f GFLOP, %.1f GFLOP/s\n",
      config.c_str(), c.num_views, threads, 1e3 * total / n, frame_flops * 1e-9,
      frame_flops * 1e-9 / (total / n));
  std::fprintf(stderr, "  process CPU time per frame: %.1f ms\n", 1e3 * cpu / n);
  const char* reference_name = bf16 ? "fp32" : "the autograd path";
  std::fprintf(stderr,
               "  largest difference to %s: %.3g m (final layer %.3g m, mean point "
               "distance %.3g m)\n",
               reference_name, max_diff, final_diff, final_mean);
  std::fprintf(stderr, "  %s on images x (1 + 1e-6): moves by %.3g m\n",
               reference_name, nudge_diff);
  std::fprintf(stderr, "  %-36s %10s %8s %10s\n", "stage", "ms", "GFLOP", "GFLOP/s");
  for (const auto& [stage, seconds] : times.seconds) {
    const double f = flops.count(stage) ? flops.at(stage) : 0.0;
    std::fprintf(stderr, "  %-36s %10.2f %8.3f %10.1f\n", stage.c_str(),
                 1e3 * seconds / n, f * 1e-9, f > 0 ? f * 1e-9 / (seconds / n) : 0.0);
  }
  state.counters["GFLOP_per_frame"] = frame_flops * 1e-9;
  state.counters["max_diff_m"] = max_diff;
  state.counters["final_mean_diff_m"] = final_mean;
  state.counters["cpu_ms_per_frame"] = 1e3 * cpu / n;
  state.counters["GFLOP_per_s"] =
      benchmark::Counter(frame_flops * 1e-9 * n, benchmark::Counter::kIsRate);
  state.counters["frames_per_s"] = benchmark::Counter(n, benchmark::Counter::kIsRate);
}

// Arguments: views, threads, precision (0 = fp32, 1 = bf16).
BENCHMARK_CAPTURE(BM_PoemStages, Released, std::string("released-dexycb"))
    ->Args({8, 1, 0})
    ->Args({8, 2, 0})
    ->Args({8, 2, 1})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_PoemStages, Shipped, std::string("models/poem_small_dexycb.pt"))
    ->Args({8, 1, 0})
    ->Args({8, 2, 0})
    ->Args({8, 2, 1})
    ->Iterations(10)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace handlabel
