// CPU time of one call of MediaPipe Hands' TFLite models in our LibTorch interpreter
// (network/detector/tflite_model.h), per view: the landmark models on a 224 x 224 crop
// and the palm detectors on a 192 x 192 image, with 1 and 2 intra-op threads.
//
//   scripts/fetch-mediapipe-models && ./build/bench/tflite_bench
// Arguments: intra-op threads. Counter: calls_per_s. The input is seeded uniform noise
// (the graph does the same work on any image). Skipped when the models are missing.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <random>

#include "core/data_dir.h"
#include "network/detector/tflite_model.h"

namespace handlabel {
namespace {

void BM_Tflite(benchmark::State& state, const std::string& name) {
  const std::string path = ShippedModelPath("mediapipe/" + name);
  if (!std::filesystem::exists(path)) {
    state.SkipWithError(
        ("missing " + path + ": run scripts/fetch-mediapipe-models").c_str());
    return;
  }
  TfliteModelOptions options;
  options.num_threads = static_cast<int>(state.range(0));
  const auto model = TfliteModel::Load(path, options);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> pixel(0.0f, 1.0f);
  std::vector<std::vector<float>> inputs;
  for (const auto& info : model->inputs()) {
    inputs.emplace_back(info.num_elements());
    for (float& p : inputs.back()) p = pixel(rng);
  }
  model->Run(inputs);  // warm-up (allocator, oneDNN primitives)
  for (auto _ : state) benchmark::DoNotOptimize(model->Run(inputs));
  state.counters["calls_per_s"] = benchmark::Counter(
      static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_Tflite, landmark_full, std::string("hand_landmark_full.tflite"))
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tflite, landmark_lite, std::string("hand_landmark_lite.tflite"))
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tflite, palm_full, std::string("palm_detection_full.tflite"))
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK_CAPTURE(BM_Tflite, palm_lite, std::string("palm_detection_lite.tflite"))
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace handlabel
