// Speed of POEM training and inference on CPU, for choosing the small configuration
// (docs/training.md): one optimisation step per 8-view sample for candidate sizes, the
// forward pass alone, and making one training sample from a synthetic frame.
//   build/bench/poem_training_bench --benchmark_filter=TrainStep
#include <benchmark/benchmark.h>
#include <torch/torch.h>

#include "hand/capsule_hand.h"
#include "network/poem/poem_loss.h"
#include "network/poem/poem_training_batch.h"
#include "openhand/builder.h"
#include "training/training_samples.h"

namespace handlabel {
namespace {

// Candidates: 0 = small (the default), 1 = small with 2 blocks and 8 depth bins,
// 2 = small at full ResNet18 width, 3 = small with 96x96 crops.
PoemConfig Candidate(int i) {
  PoemConfig c = SmallPoemConfig(8);
  if (i == 1) {
    c.num_decoder_blocks = 2;
    c.depth_bins = 8;
  } else if (i == 2) {
    c.backbone_width = 64;
  } else if (i == 3) {
    c.crop_size = 96;
  }
  return c;
}

const HandModel& OpenHand() {
  static const HandModel model = BuildOpenHand(DefaultOpenHandDesign(), {});
  return model;
}

std::vector<TrainingSample> RealSamples(int crop_size, int count) {
  SynthCaptureOptions synth;
  synth.seed = 1;
  TrainingSampleOptions o;
  o.crop_size = crop_size;
  const SynthTrainingSamples source(OpenHand(), synth, o);
  std::vector<TrainingSample> samples;
  for (int i = 0; i < count; ++i) samples.push_back(source.Sample(i));
  return samples;
}

void BM_TrainStep(benchmark::State& state) {
  torch::set_num_threads(1);
  const PoemConfig c = Candidate(static_cast<int>(state.range(0)));
  const int batch = static_cast<int>(state.range(1));
  PoemModel model = MakeRandomPoemModel(c, 1);
  torch::optim::Adam adam(model->parameters(), torch::optim::AdamOptions(1e-4));
  const PoemTrainingBatch tb = ToPoemTrainingBatch(RealSamples(c.crop_size, batch));
  const torch::Tensor regressor = PoemKeypointRegressor(OpenHand());
  for (auto _ : state) {
    TrainStep(model, adam, tb.batch, tb.targets, regressor);
  }
  state.counters["ms_per_sample"] =
      benchmark::Counter(batch / 1000.0, benchmark::Counter::kIsIterationInvariantRate |
                                             benchmark::Counter::kInvert);
  int64_t params = 0;
  for (const auto& p : model->parameters()) params += p.numel();
  state.counters["params_M"] = params / 1e6;
}
BENCHMARK(BM_TrainStep)
    ->Args({0, 4})
    ->Args({1, 4})
    ->Args({2, 4})
    ->Args({3, 4})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(5);

void BM_Inference(benchmark::State& state) {
  torch::set_num_threads(static_cast<int>(state.range(1)));
  const PoemConfig c = Candidate(static_cast<int>(state.range(0)));
  PoemModel model = MakeRandomPoemModel(c, 1);
  const std::vector<TrainingSample> samples = RealSamples(c.crop_size, 4);
  for (auto _ : state) benchmark::DoNotOptimize(PredictPoem(model, samples));
  state.counters["frames_per_s"] =
      benchmark::Counter(4.0, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_Inference)
    ->Args({0, 1})
    ->Args({0, 2})
    ->Unit(benchmark::kMillisecond)
    ->MinTime(3);

// Rendering an 8-view frame (640x480) and cutting the crops, or the crops alone.
void BM_TrainingSample(benchmark::State& state) {
  const bool reuse = state.range(0) != 0;
  SynthCaptureOptions synth;
  synth.seed = 2;
  TrainingSampleOptions o;
  o.frame_reuse = reuse ? 1000000 : 1;
  const SynthTrainingSamples source(OpenHand(), synth, o);
  int64_t i = 0;
  for (auto _ : state) benchmark::DoNotOptimize(source.Sample(i++));
}
BENCHMARK(BM_TrainingSample)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->MinTime(3);

}  // namespace
}  // namespace handlabel
