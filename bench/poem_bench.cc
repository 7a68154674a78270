// CPU cost of a POEM forward pass per multi-view frame, through the torch-free
// HandMeshPredictor (random weights: timings do not depend on the values).
//
//   ./build/bench/poem_bench [--benchmark_filter=Small]
// Arguments: views, frames per batch, intra-op threads. Counters: frames_per_s.
// Configs: "small" (half-width ResNet18, 128 crops, 1024 points, 3 blocks), the
// released architecture (ResNet34, 256 crops, 4096 points, 6 blocks), and the shipped
// models/poem_small_dexycb.pt (its own config, with the mask head if it has one).

#include <benchmark/benchmark.h>

#include <cmath>
#include <random>

#include "core/rigid3.h"
#include "network/hand_mesh_predictor.h"
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

void BM_Poem(benchmark::State& state, const std::string& config) {
  HandMeshPredictorOptions o;
  const std::string shipped = std::string(HANDLABEL_SOURCE_DIR) + "/" + config;
  if (config.find(".pt") != std::string::npos) {
    o.weights = shipped;
  } else {
    o.config = config;
  }
  o.num_views = static_cast<int>(state.range(0));
  o.batch_size = static_cast<int>(state.range(1));
  o.num_threads = static_cast<int>(state.range(2));
  auto predictor = CreateHandMeshPredictor(o);
  const auto frames =
      SyntheticFrames(o.batch_size, predictor->num_views(), predictor->crop_size());
  for (auto _ : state) benchmark::DoNotOptimize(predictor->Predict(frames));
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * o.batch_size,
                         benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_Poem, Small, std::string("small"))
    ->Args({4, 1, 1})
    ->Args({4, 4, 1})
    ->Args({4, 1, 2})
    ->Args({4, 4, 2})
    ->Args({8, 1, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Poem, Shipped, std::string("models/poem_small_dexycb.pt"))
    ->Args({8, 1, 1})
    ->Args({8, 1, 2})
    ->Args({8, 4, 2})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
// The released 8-view model takes seconds per frame: a few iterations only.
BENCHMARK_CAPTURE(BM_Poem, Released, std::string("released-dexycb"))
    ->Args({8, 1, 1})
    ->Args({8, 1, 2})
    ->Iterations(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace handlabel

BENCHMARK_MAIN();
