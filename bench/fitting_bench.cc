// Cost of fitting one multi-view frame with CeresHandFitter on the shipped open hand
// (or whatever ResolveHandModel finds), 8-camera DexYCB-like rig, 2 px keypoint noise:
//   BM_FitKeypoints             triangulation init + keypoint stages, one thread
//   BM_FitKeypointsOutliers     the same with 10 % keypoint outliers
//   BM_FitKeypointsSilhouettes  the same plus silhouette rounds (masks rendered before)
//   BM_FitFramesParallel/2      frames per second, TBB over frames on 2 threads
//
//   ./build/bench/fitting_bench [--benchmark_filter=Keypoints]
// Targets (issue 5): <= 10 ms keypoints only, <= 0.25 s with silhouettes.

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <random>
#include <vector>

#include "fitting/ceres_hand_fitter.h"
#include "fitting/silhouette_render.h"
#include "pipeline/hand_model_source.h"
#include "tests/fitting/fitting_scene.h"

namespace handlabel {
namespace {

struct BenchFrames {
  HandModel model;
  std::vector<HandFitInput> inputs;
  std::vector<HandFitInput> with_outliers;  // the same frames, 10 % outliers added
  std::vector<PixelRays> rays;
};

const BenchFrames& Frames() {
  static const BenchFrames* frames = [] {
    auto* f = new BenchFrames;
    f->model = ResolveHandModel("", HandSide::kRight).model;
    for (const RigCamera& cam : testing::DexYcbLikeRig())
      f->rays.emplace_back(cam.camera);
    std::mt19937_64 rng(5), outlier_rng(6);
    for (int i = 0; i < 8; ++i) {
      testing::SceneFrame frame = testing::RandomSceneFrame(f->model, rng);
      HandFitInput input;
      for (size_t v = 0; v < frame.views.size(); ++v) {
        input.masks.push_back(RenderHandMask(frame.mesh.vertices, f->model.faces,
                                             frame.views[v].camera, f->rays[v]));
      }
      std::vector<KeypointView> clean = frame.views;
      testing::CorruptViews(&frame.views, 2.0, 0.0, {}, rng);
      input.views = frame.views;
      f->inputs.push_back(input);
      // Its own generator: BM_FitKeypoints' frames stay those of older versions.
      testing::CorruptViews(&clean, 2.0, 0.1, {}, outlier_rng);
      input.views = clean;
      f->with_outliers.push_back(input);
    }
    return f;
  }();
  return *frames;
}

// Returns the Ceres iterations the fit took (reported as a counter: fewer iterations is
// the first place to look for speed).
int FitOne(const CeresHandFitter& fitter, HandFitInput input, bool masks) {
  if (!masks) input.masks.clear();
  const HandFitResult r = fitter.Fit(input, fitter.InitFromViews(input.views));
  benchmark::DoNotOptimize(r.params.transl);
  return r.iterations;
}

void BM_FitKeypoints(benchmark::State& state) {
  const BenchFrames& f = Frames();
  const CeresHandFitter fitter(f.model);
  size_t i = 0;
  double iterations = 0;
  for (auto _ : state)
    iterations += FitOne(fitter, f.inputs[i++ % f.inputs.size()], false);
  state.counters["iterations"] =
      benchmark::Counter(iterations, benchmark::Counter::kAvgIterations);
}
BENCHMARK(BM_FitKeypoints)->Unit(benchmark::kMillisecond);

// A detector's keypoints: 10 % of them anywhere in the image. The RANSAC of the
// initialisation then needs more pairs than on BM_FitKeypoints' clean frames.
void BM_FitKeypointsOutliers(benchmark::State& state) {
  const BenchFrames& f = Frames();
  const CeresHandFitter fitter(f.model);
  size_t i = 0;
  for (auto _ : state)
    FitOne(fitter, f.with_outliers[i++ % f.with_outliers.size()], false);
}
BENCHMARK(BM_FitKeypointsOutliers)->Unit(benchmark::kMillisecond);

// The baseline's initialisation alone (robust triangulation + 3D alignment), the part of
// BM_FitKeypoints before the keypoint stages.
void BM_InitFromViews(benchmark::State& state) {
  const BenchFrames& f = Frames();
  const CeresHandFitter fitter(f.model);
  size_t i = 0;
  for (auto _ : state) {
    const HandParams init = fitter.InitFromViews(f.inputs[i++ % f.inputs.size()].views);
    benchmark::DoNotOptimize(init.transl);
  }
}
BENCHMARK(BM_InitFromViews)->Unit(benchmark::kMillisecond);

void BM_FitKeypointsSilhouettes(benchmark::State& state) {
  const BenchFrames& f = Frames();
  const CeresHandFitter fitter(f.model);
  size_t i = 0;
  for (auto _ : state) {
    HandFitInput input = f.inputs[i++ % f.inputs.size()];
    FitOne(fitter, input, true);
  }
}
BENCHMARK(BM_FitKeypointsSilhouettes)->Unit(benchmark::kMillisecond);

void BM_FitFramesParallel(benchmark::State& state) {
  const BenchFrames& f = Frames();
  const CeresHandFitter fitter(f.model);
  tbb::global_control limit(tbb::global_control::max_allowed_parallelism, state.range(0));
  for (auto _ : state) {
    tbb::parallel_for(size_t(0), f.inputs.size(),
                      [&](size_t i) { FitOne(fitter, f.inputs[i], false); });
  }
  state.counters["frames_per_second"] =
      benchmark::Counter(static_cast<double>(state.iterations() * f.inputs.size()),
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_FitFramesParallel)
    ->Arg(1)
    ->Arg(2)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace handlabel
