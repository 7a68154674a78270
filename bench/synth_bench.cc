// Synthetic capture speed, single-threaded: views per second at 256x256 for a hand
// holding an object (target >= 200 views/s).
//
//   ./build/bench/synth_bench
// RenderView: one view of a fixed scene (rasterise hand + object, shade, masks,
//   keypoint visibility, cluttered background): the per-view cost.
// GenerateFrame/model/N: a whole frame with N cameras as SynthGenerator makes it (scene
//   sampling, N views, simulated detections), reported as views/s.
// WriteFrame: GenerateFrame (open hand, 8 cameras) plus PNG encoding of image, mask,
// object mask and
//   detection mask (no disk I/O), per view.
// Argument 0: the built-in capsule hand (~1150 vertices, ~2100 faces); 1: the shipped
// open hand (models/open_hand_right.npz, 778 vertices, 1538 faces, like MANO).

#include <benchmark/benchmark.h>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "image/image.h"
#include "pipeline/hand_model_source.h"

namespace handlabel {
namespace {

HandModel BenchModel(int which) {
  return which == 0 ? MakeCapsuleHand(HandSide::kRight)
                    : ResolveHandModel("", HandSide::kRight).model;
}

SynthCaptureOptions BenchOptions(int cameras) {
  SynthCaptureOptions o;
  o.rig.preset = "random";
  o.rig.num_cameras = cameras;
  o.rig.width = 256;
  o.rig.height = 256;
  o.scene.objects = true;
  o.scene.max_objects = 1;
  o.seed = 3;
  return o;
}

void BM_RenderView(benchmark::State& state) {
  const SynthGenerator gen(BenchModel(static_cast<int>(state.range(0))),
                           MakePresetRig(BenchOptions(8).rig, 3), BenchOptions(8));
  const SynthFrame frame = gen.Generate(0);
  const PixelRays rays(gen.rig()[0].camera);
  std::mt19937_64 rng(1);
  for (auto _ : state) {
    const SynthView view =
        RenderSynthView(frame.scene, gen.rig()[0], rays, gen.options().view, rng);
    benchmark::DoNotOptimize(view.hand_pixels);
  }
  state.counters["views/s"] =
      benchmark::Counter(state.iterations(), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RenderView)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

void BM_GenerateFrame(benchmark::State& state) {
  const int cameras = static_cast<int>(state.range(1));
  const SynthCaptureOptions o = BenchOptions(cameras);
  const SynthGenerator gen(BenchModel(static_cast<int>(state.range(0))),
                           MakePresetRig(o.rig, o.seed), o);
  int f = 0;
  for (auto _ : state) {
    const SynthFrame frame = gen.Generate(f++);
    benchmark::DoNotOptimize(frame.views.size());
  }
  state.counters["views/s"] =
      benchmark::Counter(state.iterations() * cameras, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_GenerateFrame)
    ->Args({0, 1})
    ->Args({0, 8})
    ->Args({1, 1})
    ->Args({1, 8})
    ->Unit(benchmark::kMillisecond);

void BM_WriteFrame(benchmark::State& state) {
  const int cameras = 8;
  const SynthCaptureOptions o = BenchOptions(cameras);
  const SynthGenerator gen(BenchModel(1), MakePresetRig(o.rig, o.seed), o);
  int f = 0;
  for (auto _ : state) {
    const SynthFrame frame = gen.Generate(f++);
    size_t bytes = 0;
    for (int c = 0; c < cameras; ++c) {
      bytes += EncodePng(frame.views[c].rgb).size() +
               EncodePng(frame.views[c].hand_mask).size() +
               EncodePng(frame.views[c].object_mask).size() +
               EncodePng(frame.detections[c].mask).size();
    }
    benchmark::DoNotOptimize(bytes);
  }
  state.counters["views/s"] =
      benchmark::Counter(state.iterations() * cameras, benchmark::Counter::kIsRate);
}
BENCHMARK(BM_WriteFrame)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace handlabel
