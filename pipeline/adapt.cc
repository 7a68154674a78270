#include "pipeline/adapt.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <set>

#include "capture/capture_format.h"
#include "capture/capture_reader.h"
#include "core/atomic_file.h"
#include "core/data_dir.h"
#include "core/errors.h"
#include "core/file_lock.h"
#include "core/json_util.h"
#include "core/option_checks.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "pipeline/adapt_run.h"
#include "pipeline/detect_capture.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"

namespace handlabel {
namespace adapt {

namespace fs = std::filesystem;

nlohmann::json ReadIfExists(const std::string& path) {
  return fs::exists(path) ? ReadJsonFileStrict(path) : nlohmann::json();
}

// A job over the capture's detections without masks (their 2D is the evidence).
JobConfig CaptureJob(const AdaptRun& run, const std::string& name,
                     const std::string& out) {
  JobConfig job;
  job.source_file = "handlabel adapt";
  job.name = name;
  job.input_format = "native";
  job.input_path = fs::path(run.o.capture_dir).lexically_normal().string();
  job.threads = run.o.threads;
  job.keypoints = KeypointSource::kFiles;
  job.keypoint_files = "detections";
  job.masks = MaskSource::kNone;
  job.output_dir = out;
  job.overlays = run.o.overlays;
  return job;
}

LabelSummary RunJob(const AdaptRun& run, const JobConfig& job) {
  job.Check(job.source_file);
  const BuiltLabelStages stages = BuildLabelStages(job);
  LabelRunOptions options;
  options.resume = true;
  options.log = run.log;
  return RunLabelJob(job, stages.Set(), options);
}

// The frames the fit labelled (it fails a frame whose detections do not pin the hand
// down, e.g. in fewer than two views): only they can teach or measure.
std::vector<std::string> WithFitLabel(const AdaptRun& run,
                                      const std::vector<std::string>& frames) {
  std::vector<std::string> labelled;
  for (const std::string& id : frames) {
    if (fs::exists(LabelFilePath(run.Path("fit"), id))) labelled.push_back(id);
  }
  return labelled;
}

namespace {

using Clock = std::chrono::steady_clock;

constexpr char kSource[] = "command line";
constexpr char kShippedWeights[] = "poem_small_dexycb.pt";
// The default held-out block: the last frames, after a gap whose frames neither train
// nor validate (at 30 fps the frames next to a held-out one are near-copies of it).
constexpr int kHeldoutFrames = 16;
constexpr int kHeldoutGap = 4;
constexpr int kMinFramesForHeldout = 40;

// The split: the held-out frames, and the training frames (the rest, less the gap
// before a default held-out block).
void SplitFrames(AdaptRun* run) {
  const int n = static_cast<int>(run->frames.size());
  std::set<std::string> unused;
  if (!run->o.heldout.empty()) {
    run->heldout = SelectFrames(run->frames, run->o.heldout, kSource, "--heldout");
  } else if (n >= kMinFramesForHeldout) {
    run->heldout.assign(run->frames.end() - kHeldoutFrames, run->frames.end());
    unused.insert(run->frames.end() - kHeldoutFrames - kHeldoutGap,
                  run->frames.end() - kHeldoutFrames);
  }
  const std::set<std::string> held(run->heldout.begin(), run->heldout.end());
  for (const std::string& id : run->frames) {
    if (!held.count(id) && !unused.count(id)) run->train.push_back(id);
  }
  if (run->train.empty()) {
    throw InputError(kSource, "--heldout", "frames left to train on",
                     "every frame of the capture held out");
  }
}

constexpr char kRunLock[] = "adapt.lock";

// One adapt process per folder at a time (core/file_lock.h): the run's label jobs lock
// <out>/.handlabel.lock themselves, so the run holds <out>/adapt.lock.
FileLock LockRun(const AdaptRun& run) {
  fs::create_directories(run.out);
  return LockFolderForWriting(run.out.string(), run.Path(kRunLock), "adapt", kSource,
                              "--out");
}

bool IsEmptyBesidesLock(const fs::path& dir) {
  for (const auto& entry : fs::directory_iterator(dir)) {
    if (entry.path().filename() != kRunLock) return false;
  }
  return true;
}

// adapt.json: a folder holds one run; a later command must ask for the same one.
void ClaimFolder(const AdaptRun& run) {
  const std::string path = run.Path("adapt.json");
  const nlohmann::json wanted = AdaptOptionsJson(run.o);
  if (fs::exists(path)) {
    nlohmann::json had = ReadJsonFileStrict(path);
    // Runs from before synthetic samples trained on the capture alone.
    if (!had.contains("synth_share")) had["synth_share"] = 0.0;
    for (const auto& [key, value] : wanted.items()) {
      if (!had.contains(key) || had[key] != value) {
        throw InputError(path, key,
                         (had.contains(key) ? had[key].dump() : "nothing") +
                             ", the run's in this folder (another run needs another "
                             "--out)",
                         value.dump());
      }
    }
    run.Say("continuing the run in " + run.out.string());
    return;
  }
  if (fs::exists(run.out) && !IsEmptyBesidesLock(run.out)) {
    throw InputError(run.out.string(), "--out",
                     "a new or empty folder (or an adapt run's)",
                     "a folder with other files and no adapt.json");
  }
  fs::create_directories(run.out / "stages");
  WriteFileAtomically(path, wanted.dump(1) + "\n");
}

void LoadProgress(AdaptRun* run) {
  const std::string path = run->Path("progress.json");
  if (fs::exists(path)) run->progress = ReadJsonFileStrict(path)["seconds"];
}

// Runs a stage unless an earlier run finished it; records its seconds.
template <typename StageFn>
void RunStage(AdaptRun* run, const std::string& name, StageFn&& stage) {
  const std::string marker = run->Path("stages/" + name + ".done");
  if (fs::exists(marker)) {
    run->Say(name + ": done in an earlier run");
    return;
  }
  run->Say(name + ": started");
  const Clock::time_point t0 = Clock::now();
  stage();
  const double seconds = SecondsSince(t0);
  run->progress[name] = run->progress.value(name, 0.0) + seconds;
  WriteFileAtomically(
      run->Path("progress.json"),
      nlohmann::json{{"seconds", run->progress}, {"total_seconds", run->ElapsedSeconds()}}
              .dump(1) +
          "\n");
  WriteFileAtomically(marker, nlohmann::json{{"seconds", seconds}}.dump() + "\n");
  run->Say(name + ": done in " + FormatNumber(std::round(seconds)) + " s");
}

void FitStage(const AdaptRun& run) {
  JobConfig job = CaptureJob(run, "adapt-fit", run.Path("fit"));
  job.refine_mode = RefineMode::kAlways;
  job.overlays = false;
  RunJob(run, job);
}

void DetectStage(const AdaptRun& run) {
  if (CaptureReader(run.o.capture_dir).Has(kFileDetections)) {
    run.Say("the capture has detections: they are the 2D evidence");
    WriteFileAtomically(run.Path("detect.json"), "{\"ran\": false}\n");
    return;
  }
  DetectCaptureOptions detect;
  detect.threads = run.o.threads;
  const DetectCaptureSummary s =
      DetectCapture(run.o.capture_dir, detect, [&run](int done, int total) {
        if (done % 10 == 0 || done == total) {
          run.Say("detect: " + std::to_string(done) + "/" + std::to_string(total));
        }
      });
  run.Say("detect: a hand in " + std::to_string(s.views_detected) + " of " +
          std::to_string(s.views) + " views");
  WriteFileAtomically(run.Path("detect.json"),
                      nlohmann::json{{"ran", true},
                                     {"views", s.views},
                                     {"views_detected", s.views_detected},
                                     {"frames_with_hand", s.frames_with_hand}}
                              .dump(1) +
                          "\n");
}

void LabelStage(const AdaptRun& run) {
  JobConfig job = CaptureJob(run, "adapt-label", run.out.string());
  job.network_weights = run.Path("network.pt");
  job.refine_mode = RefineMode::kFallback;
  const nlohmann::json heldout = ReadIfExists(run.Path("heldout/heldout.json"));
  if (heldout.is_object() && heldout.contains("thresholds")) {
    const nlohmann::json& refine = heldout["thresholds"]["refine"];
    job.quality.max_reprojection_px = refine["max_reprojection_px"];
    job.quality.max_view_disagreement_mm = refine["max_view_disagreement_mm"];
    job.quality.max_detector_rms_px = refine["max_detector_rms_px"];
  }
  RunJob(run, job);
}

// The run's frames (sorted, as jobs number them), cameras and weights.
AdaptRun PrepareRun(const AdaptOptions& options, std::ostream* log) {
  options.Check(kSource);
  AdaptRun run;
  run.o = options;
  run.log = log;
  run.o.capture_dir = fs::absolute(options.capture_dir).lexically_normal().string();
  run.out = fs::absolute(options.out_dir).lexically_normal();
  if (run.o.weights.empty()) run.o.weights = ShippedModelPath(kShippedWeights);
  if (!fs::exists(run.o.weights)) {
    throw InputError(kSource, "--weights", "a POEM weights file",
                     run.o.weights + ": no such file");
  }
  run.o.weights = fs::absolute(run.o.weights).lexically_normal().string();
  const CaptureReader capture(run.o.capture_dir);
  run.num_cameras = capture.num_cameras();
  for (int f = 0; f < capture.num_frames(); ++f)
    run.frames.push_back(capture.frame_id(f));
  std::sort(run.frames.begin(), run.frames.end());
  SplitFrames(&run);
  return run;
}

// The stages in order, each skipped when an earlier run finished it.
AdaptSummary RunStages(const AdaptOptions& options, std::ostream* log) {
  AdaptRun run = PrepareRun(options, log);
  const FileLock writer = LockRun(run);
  ClaimFolder(run);
  LoadProgress(&run);
  run.Say(std::to_string(run.frames.size()) + " frames, " +
          std::to_string(run.train.size()) + " to train on, " +
          std::to_string(run.heldout.size()) + " held out; budget " +
          FormatNumber(run.o.budget_minutes) + " min");
  RunStage(&run, "detect", [&] { DetectStage(run); });
  RunStage(&run, "fit", [&] { FitStage(run); });
  if (run.o.synth_share > 0)
    RunStage(&run, "backgrounds", [&] { BackgroundsStage(run); });
  RunStage(&run, "train", [&] { TrainStage(&run); });
  RunStage(&run, "export", [&] { ExportStage(run); });
  if (!run.heldout.empty()) RunStage(&run, "heldout", [&] { HeldoutStage(run); });
  RunStage(&run, "label", [&] { LabelStage(run); });
  AdaptSummary summary;
  summary.network_path = run.Path("network.pt");
  summary.labels_dir = run.Path("labels");
  summary.card = ModelCard(run);
  WriteFileAtomically(run.Path("model_card.json"), summary.card.dump(1) + "\n");
  WriteFileAtomically(run.Path("model_card.md"), ModelCardMarkdown(summary.card));
  WriteFileAtomically(run.Path("new_recordings.yaml"), JobForNewRecordings(run));
  return summary;
}

}  // namespace
}  // namespace adapt

void AdaptOptions::Check(const std::string& source) const {
  if (capture_dir.empty())
    throw InputError(source, "--capture", "a capture folder", "empty");
  if (out_dir.empty()) throw InputError(source, "--out", "an output folder", "empty");
  RequireGreater(source, "--budget", budget_minutes, 0);
  RequireAtLeast(source, "--threads", threads, 1);
  RequireGreater(source, "--learning-rate", learning_rate, 0);
  RequireGreater(source, "--accept-mm", accept_mm, 0);
  RequireInRange(source, "--synth-share", synth_share, 0.0, 1.0);
  selection.Check(source);
}

nlohmann::json AdaptOptionsJson(const AdaptOptions& o) {
  return {{"capture", o.capture_dir},
          {"weights", o.weights},
          {"heldout", o.heldout},
          {"label_min_views", o.selection.min_views},
          {"label_max_rms_px", o.selection.max_view_rms_px},
          {"learning_rate", o.learning_rate},
          {"seed", o.seed},
          {"accept_mm", o.accept_mm},
          {"synth_share", o.synth_share}};
}

AdaptSummary RunAdaptation(const AdaptOptions& options, std::ostream* log) {
  return adapt::RunStages(options, log);
}

}  // namespace handlabel
