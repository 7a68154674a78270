// Throughput of the labeling runner (frames/s) against thread count, on a synthetic
// DexYCB-like capture (8 cameras, 320x240, simulated detections and masks) labelled
// fitting-only with the Ceres fitter, with and without the silhouette term. Each
// iteration labels every frame again (--force) into a scratch folder.
//   build/bench/label_bench --benchmark_filter=Label
#include <benchmark/benchmark.h>

#include <filesystem>

#include "capture/synth_capture.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_job.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
constexpr int kFrames = 8;

const std::string& CaptureDir() {
  static const std::string dir = [] {
    const std::string d =
        (fs::temp_directory_path() / "handlabel_label_bench_capture").string();
    SynthCaptureOptions o;
    o.rig.preset = "dexycb";
    o.rig.width = 320;
    o.rig.height = 240;
    o.num_frames = kFrames;
    o.seed = 5;
    o.num_threads = 2;
    WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, d, "builtin:capsule", true);
    return d;
  }();
  return dir;
}

void BM_LabelFitOnly(benchmark::State& state) {
  JobConfig job;
  job.source_file = "label_bench";
  job.hand_model = "capsule";
  job.input_path = CaptureDir();
  job.output_dir = (fs::temp_directory_path() / "handlabel_label_bench_out").string();
  job.refine_mode = RefineMode::kAlways;
  job.keypoints = KeypointSource::kFiles;
  job.masks = state.range(1) ? MaskSource::kFiles : MaskSource::kNone;
  job.threads = static_cast<int>(state.range(0));
  job.overlays = false;
  const BuiltLabelStages stages = BuildLabelStages(job);
  LabelRunOptions options;
  options.force = true;
  for (auto _ : state) RunLabelJob(job, stages.Set(), options);
  state.counters["frames/s"] = benchmark::Counter(double(kFrames) * state.iterations(),
                                                  benchmark::Counter::kIsRate);
  state.SetLabel(state.range(1) ? "keypoints + silhouettes" : "keypoints");
}
BENCHMARK(BM_LabelFitOnly)
    ->ArgsProduct({{1, 2}, {0, 1}})
    ->ArgNames({"threads", "masks"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime()
    ->Iterations(1);

}  // namespace
}  // namespace handlabel
