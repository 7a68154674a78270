#include "pipeline/adapt.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "capture/capture_format.h"
#include "capture/capture_reader.h"
#include "core/atomic_file.h"
#include "core/data_dir.h"
#include "core/errors.h"
#include "core/json_util.h"
#include "core/option_checks.h"
#include "core/text.h"
#include "hand/metrics.h"
#include "network/poem/loss_plot.h"
#include "network/poem/poem_trainer.h"
#include "pipeline/adapt_thresholds.h"
#include "pipeline/build_info.h"
#include "pipeline/detect_capture.h"
#include "pipeline/fit_capture.h"
#include "pipeline/label_job.h"
#include "pipeline/label_record.h"
#include "pipeline/label_stage_factory.h"
#include "pipeline/train_config.h"
#include "training/capture_training_samples.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

constexpr char kSource[] = "command line";
constexpr char kShippedWeights[] = "poem_small_dexycb.pt";
// The default held-out block: the last frames, after a gap whose frames neither train
// nor validate (at 30 fps the frames next to a held-out one are near-copies of it).
constexpr int kHeldoutFrames = 16;
constexpr int kHeldoutGap = 4;
constexpr int kMinFramesForHeldout = 40;
// Steps timed before the plan (the first 10 include the start-up).
constexpr int64_t kTimingSteps = 20;
// The averaged checkpoints: those of the last 30 % of the steps, where the rate is low.
constexpr double kDecayAt = 0.7;
constexpr int kMaxBatchNormSamples = 256;

double SecondsSince(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

std::string CpuModelName() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("model name", 0) == 0) {
      const size_t colon = line.find(':');
      if (colon != std::string::npos) return line.substr(colon + 2);
    }
  }
  return "unknown";
}

// The run's state: its options, folders, frames and the seconds each stage took.
struct AdaptRun {
  AdaptOptions o;
  std::ostream* log = nullptr;
  fs::path out;
  std::vector<std::string> frames, train, heldout;
  int num_cameras = 0;
  nlohmann::json progress = nlohmann::json::object();  // stage -> seconds

  void Say(const std::string& line) const {
    if (log) *log << "handlabel adapt: " << line << std::endl;
  }
  std::string Path(const std::string& relative) const { return (out / relative).string(); }
  double ElapsedSeconds() const {
    double s = 0;
    for (const auto& [stage, seconds] : progress.items()) s += seconds.get<double>();
    return s;
  }
};

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

// adapt.json: a folder holds one run; a later command must ask for the same one.
void ClaimFolder(const AdaptRun& run) {
  const std::string path = run.Path("adapt.json");
  const nlohmann::json wanted = AdaptOptionsJson(run.o);
  if (fs::exists(path)) {
    const nlohmann::json had = ReadJsonFileStrict(path);
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
  if (fs::exists(run.out) && !fs::is_empty(run.out)) {
    throw InputError(run.out.string(), "--out", "a new or empty folder (or an adapt run's)",
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
  WriteFileAtomically(run->Path("progress.json"),
                      nlohmann::json{{"seconds", run->progress},
                                     {"total_seconds", run->ElapsedSeconds()}}
                              .dump(1) +
                          "\n");
  WriteFileAtomically(marker, nlohmann::json{{"seconds", seconds}}.dump() + "\n");
  run->Say(name + ": done in " + FormatNumber(std::round(seconds)) + " s");
}

void DetectStage(const AdaptRun& run) {
  if (CaptureReader(run.o.capture_dir).Has(kFileDetections)) {
    run.Say("the capture has detections: they are the 2D evidence");
    WriteFileAtomically(run.Path("detect.json"), "{\"ran\": false}\n");
    return;
  }
  DetectCaptureOptions detect;
  detect.hands.num_threads = run.o.threads;
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

nlohmann::json ReadIfExists(const std::string& path) {
  return fs::exists(path) ? ReadJsonFileStrict(path) : nlohmann::json();
}

// A job over the capture's detections without masks (their 2D is the evidence).
JobConfig CaptureJob(const AdaptRun& run, const std::string& name, const std::string& out) {
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

void FitStage(const AdaptRun& run) {
  JobConfig job = CaptureJob(run, "adapt-fit", run.Path("fit"));
  job.refine_mode = RefineMode::kAlways;
  job.overlays = false;
  RunJob(run, job);
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

CaptureTrainingInputs TrainingInputs(const AdaptRun& run) {
  CaptureTrainingInputs in;
  in.capture_dir = run.o.capture_dir;
  in.labels_dir = run.Path("fit/labels");
  const std::vector<std::string> train = WithFitLabel(run, run.train);
  if (train.empty()) {
    throw InputError(run.Path("fit/labels"), "labels",
                     "fit labels of some training frames (the fit failed every one: "
                     "see fit/summary.md)",
                     "none of " + std::to_string(run.train.size()));
  }
  in.train_frames = Join(train, ",");
  in.val_frames = Join(WithFitLabel(run, run.heldout), ",");
  in.selection = run.o.selection;
  return in;
}

// The run's training: the starting weights' network on the capture's views.
TrainConfig AdaptTrainConfig(const AdaptRun& run) {
  TrainConfig c;
  c.source_file = "handlabel adapt";
  c.network_name = "the starting weights' (" + run.o.weights + ")";
  c.network = PoemCheckpointConfig(run.o.weights);
  c.network.num_views = run.num_cameras;
  c.synth.seed = run.o.seed;  // the capture samples' order and augmentation
  PoemTrainerOptions& t = c.trainer;
  t.learning_rate = run.o.learning_rate;
  t.warmup_steps = kTimingSteps;
  t.decay_at = kDecayAt;
  t.decay_factor = 0.1;
  t.keep_checkpoints = 3;
  t.log_every = 10;
  t.validate_at_start = true;
  t.seed = run.o.seed;
  t.threads = run.o.threads;
  t.out_dir = run.Path("train");
  t.init_weights = run.o.weights;
  return c;
}

// The capture's labelled frames as training and held-out samples.
struct AdaptSamples {
  CaptureTrainingData data;
  std::unique_ptr<CaptureTrainingSamples> train, heldout, batch_norm;
};

AdaptSamples LoadSamples(const AdaptRun& run, const TrainConfig& c, const HandModel& hand) {
  AdaptSamples s;
  s.data = LoadCaptureTrainingData(TrainingInputs(run), hand.num_vertices());
  s.train = std::make_unique<CaptureTrainingSamples>(*s.data.source, s.data.train,
                                                     CaptureSampleOptionsFor(c, false));
  // Batch-norm statistics are measured on the training frames as inference crops them.
  s.batch_norm = std::make_unique<CaptureTrainingSamples>(
      *s.data.source, s.data.train, CaptureSampleOptionsFor(c, true));
  if (!s.data.validation.empty()) {
    s.heldout = std::make_unique<CaptureTrainingSamples>(
        *s.data.source, s.data.validation, CaptureSampleOptionsFor(c, true));
  }
  return s;
}

PoemTrainSummary TrainUntil(const AdaptRun& run, const TrainConfig& c, const HandModel& hand,
                            const AdaptSamples& s, int64_t stop_at) {
  PoemTrainerOptions t = c.trainer;
  t.validation_samples = std::max<int>(1, static_cast<int>(s.data.validation.size()));
  if (!s.heldout) {
    t.validate_every = 0;
    t.validate_at_start = false;
  }
  PoemTrainerHooks hooks;
  hooks.progress = [&run](const std::string& line) { run.Say("train: " + line); };
  const std::string dir = t.out_dir;
  hooks.logs_written = [dir] { DrawTrainingCurves(dir); };
  PoemTrainer trainer(c.network, hand, *s.train, s.heldout.get(), t, hooks);
  return trainer.Run(/*resume=*/true, stop_at);
}

// Seconds per step from loss.csv's wall clock between the timing run's two rows (the
// first row also holds the start-up).
double MeasuredSecondsPerStep(const std::string& train_dir) {
  const std::string path = train_dir + "/loss.csv";
  const CsvTable loss = ReadCsvTable(path);
  const std::vector<double> steps = loss.Column("step"), wall = loss.Column("wall_s");
  for (size_t i = 1; i < steps.size() && i < wall.size(); ++i) {
    if (steps[i] == kTimingSteps && steps[i] > steps[i - 1] && wall[i] > wall[i - 1]) {
      return (wall[i] - wall[i - 1]) / (steps[i] - steps[i - 1]);
    }
  }
  throw InputError(path, "wall_s", "rows at steps 10 and 20 of the timing run",
                   std::to_string(steps.size()) + " rows");
}

// How many steps the budget pays for: what is left of it after the stages so far and a
// reserve for the ones after training (export, held-out jobs, the label job, which
// fits where the network fails: about as long as the fit stage).
nlohmann::json PlanTraining(const AdaptRun& run, double seconds_per_step) {
  const double reserve = 1.2 * run.progress.value("fit", 0.0) + 150;
  const double budget = run.o.budget_minutes * 60;
  const double left = budget - run.ElapsedSeconds() - reserve;
  const int64_t extra =
      left > 0 ? static_cast<int64_t>(0.95 * left / seconds_per_step) : kTimingSteps;
  const int64_t steps = kTimingSteps + std::max<int64_t>(extra, kTimingSteps);
  const int64_t every = std::max<int64_t>(10, (steps / 20 + 5) / 10 * 10);
  return {{"steps", steps},
          {"seconds_per_step", seconds_per_step},
          {"budget_seconds", budget},
          {"seconds_before_training", run.ElapsedSeconds()},
          {"reserve_seconds", reserve},
          {"checkpoint_every", every},
          {"validate_every", std::max<int64_t>(100, (steps / 10 + 50) / 100 * 100)},
          {"budget_too_small", !(left > 0)},
          {"cpu", CpuModelName()},
          {"threads", run.o.threads}};
}

void ApplyPlan(const nlohmann::json& plan, TrainConfig* c) {
  c->trainer.steps = plan["steps"].get<int64_t>();
  c->trainer.checkpoint_every = plan["checkpoint_every"].get<int64_t>();
  c->trainer.keep_every = c->trainer.checkpoint_every;
  c->trainer.validate_every = plan["validate_every"].get<int64_t>();
}

void TrainStage(AdaptRun* run) {
  TrainConfig c = AdaptTrainConfig(*run);
  std::string hand_source;
  const HandModel hand = LoadTrainingHandModel(c, &hand_source);
  const AdaptSamples samples = LoadSamples(*run, c, hand);
  WriteFileAtomically(run->Path("train/capture_labels.json"),
                      LabelSelectionJson(run->o.selection, samples.data.selection).dump(1) +
                          "\n");
  run->Say("train: " + std::to_string(samples.data.train.size()) + " of " +
           std::to_string(run->train.size()) + " training frames kept (" +
           std::to_string(run->train.size() - samples.data.selection.size()) +
           " without a fit label; train/capture_labels.json), " +
           std::to_string(samples.data.validation.size()) + " of " +
           std::to_string(run->heldout.size()) + " held-out frames with a fit label");
  const std::string plan_path = run->Path("train/plan.json");
  if (!fs::exists(plan_path)) {
    const Clock::time_point t0 = Clock::now();
    c.trainer.steps = 1000000;  // only the warm-up's steps run before the plan
    c.trainer.checkpoint_every = kTimingSteps;
    c.trainer.validate_every = 0;
    TrainUntil(*run, c, hand, samples, kTimingSteps);
    run->progress["train_timing"] = SecondsSince(t0);
    const nlohmann::json plan =
        PlanTraining(*run, MeasuredSecondsPerStep(c.trainer.out_dir));
    WriteFileAtomically(plan_path, plan.dump(1) + "\n");
    run->progress.erase("train_timing");  // the stage's own time counts it
  }
  const nlohmann::json plan = ReadJsonFileStrict(plan_path);
  run->Say("train: " + plan["steps"].dump() + " steps planned at " +
           FormatNumber(plan["seconds_per_step"].get<double>()) + " s/step (" +
           plan_path + ")");
  ApplyPlan(plan, &c);
  TrainUntil(*run, c, hand, samples, -1);
}

// The checkpoints of the last 30 % of the steps (the latest one if none).
std::vector<std::string> AveragedCheckpoints(const std::string& train_dir, int64_t steps) {
  std::vector<std::string> paths;
  const int64_t first = static_cast<int64_t>(std::ceil(kDecayAt * steps));
  for (const auto& entry : fs::directory_iterator(train_dir + "/checkpoints")) {
    const std::string name = entry.path().filename().string();
    if (name.rfind("step_", 0) != 0 || entry.path().extension() != ".pt") continue;
    if (std::stoll(name.substr(5)) >= first) paths.push_back(entry.path().string());
  }
  std::sort(paths.begin(), paths.end());
  if (paths.empty()) paths.push_back(LatestPoemCheckpointModel(train_dir));
  return paths;
}

void ExportStage(const AdaptRun& run) {
  const TrainConfig c = AdaptTrainConfig(run);
  std::string hand_source;
  const HandModel hand = LoadTrainingHandModel(c, &hand_source);
  const AdaptSamples samples = LoadSamples(run, c, hand);
  const nlohmann::json plan = ReadJsonFileStrict(run.Path("train/plan.json"));
  const std::vector<std::string> paths =
      AveragedCheckpoints(c.trainer.out_dir, plan["steps"].get<int64_t>());
  const int batch = c.trainer.batch_size;
  const int bn_samples =
      std::min<int>(kMaxBatchNormSamples,
                    4 * static_cast<int>(samples.data.train.size())) / batch * batch;
  ExportPoemCheckpointAverageAsHalf(paths, run.Path("network.pt"),
                                    samples.batch_norm.get(), bn_samples, batch);
  nlohmann::json names = nlohmann::json::array();
  for (const std::string& p : paths) names.push_back(fs::path(p).filename().string());
  WriteFileAtomically(run.Path("export.json"),
                      nlohmann::json{{"averaged_checkpoints", names},
                                     {"batch_norm_samples", bn_samples}}
                              .dump(1) +
                          "\n");
}

// A job's held-out answers judged against their fit labels.
std::vector<JudgedAnswer> JudgeAnswers(const AdaptRun& run, const std::string& job_dir,
                                       double* mpvpe_mm) {
  std::vector<JudgedAnswer> answers;
  double vertices = 0;
  for (const std::string& id : WithFitLabel(run, run.heldout)) {
    const LabelRecord answer = ReadLabelFile(LabelFilePath(job_dir, id));
    const LabelRecord fit = ReadLabelFile(LabelFilePath(run.Path("fit"), id));
    answers.push_back(
        {1000 * MeanPointError(answer.mesh.keypoints, fit.mesh.keypoints), answer.quality});
    vertices += 1000 * MeanPointError(answer.mesh.vertices, fit.mesh.vertices);
  }
  *mpvpe_mm = vertices / std::max<size_t>(answers.size(), 1);
  return answers;
}

nlohmann::json AnswersJson(const std::vector<JudgedAnswer>& answers, double mpvpe_mm) {
  double joints = 0;
  int passed = 0;
  for (const JudgedAnswer& a : answers) {
    joints += a.error_mm;
    bool all = true;
    for (const QualityFlag& f : a.quality.flags) all = all && f.passed;
    passed += all;
  }
  return {{"frames", answers.size()},
          {"mpjpe_mm_vs_fit_labels", joints / std::max<size_t>(answers.size(), 1)},
          {"mpvpe_mm_vs_fit_labels", mpvpe_mm},
          {"passed_every_check", passed}};
}

// The adapted network's thresholds, chosen on its held-out answers
// (adapt_thresholds.h), for the label stage (heldout.json's thresholds).
void ChooseAdaptedThresholds(const AdaptRun& run, const std::vector<JudgedAnswer>& answers,
                             const QualityThresholds& current, nlohmann::json* result) {
  ThresholdStudy study;
  const QualityThresholds chosen =
      ChooseThresholds(answers, current, run.o.accept_mm, &study);
  nlohmann::json json = study.ToJson();
  json["refine"] = {{"max_reprojection_px", chosen.max_reprojection_px},
                    {"max_view_disagreement_mm", chosen.max_view_disagreement_mm},
                    {"max_detector_rms_px", chosen.max_detector_rms_px}};
  (*result)["thresholds"] = json;
}

// The network alone (no refine) before and after, on the held-out frames.
void HeldoutStage(const AdaptRun& run) {
  nlohmann::json result = nlohmann::json::object();
  const std::pair<std::string, std::string> runs[] = {{"before", run.o.weights},
                                                      {"after", run.Path("network.pt")}};
  for (auto [name, weights] : runs) {
    const int views = PoemCheckpointConfig(weights).num_views;
    if (views != run.num_cameras) {
      // The starting weights as they start the training: at the capture's view count.
      const std::string converted = run.Path(
          "heldout/start_weights_" + std::to_string(run.num_cameras) + "_views.pt");
      WritePoemCheckpointForViews(weights, run.num_cameras, converted);
      run.Say("heldout: the starting weights are for " + std::to_string(views) +
              " views, measured at the capture's " + std::to_string(run.num_cameras) +
              " (" + converted + ")");
      weights = converted;
    }
    const std::string dir = run.Path("heldout/" + name);
    JobConfig job = CaptureJob(run, "adapt-heldout-" + name, dir);
    job.frames = Join(run.heldout, ",");
    job.network_weights = weights;
    job.refine_mode = RefineMode::kOff;
    const LabelSummary summary = RunJob(run, job);
    double mpvpe_mm = 0;
    const std::vector<JudgedAnswer> answers = JudgeAnswers(run, dir, &mpvpe_mm);
    result[name] = AnswersJson(answers, mpvpe_mm);
    result[name]["weights"] = weights;
    if (name == "after") ChooseAdaptedThresholds(run, answers, job.quality, &result);
    result[name]["job_metrics"] = summary.ToJson().value("metrics", nlohmann::json());
    run.Say("heldout: network " + name + ": " +
            FormatNumber(std::round(10 * result[name]["mpjpe_mm_vs_fit_labels"]
                                             .get<double>()) /
                         10) +
            " mm from the fit labels (" + dir + ")");
  }
  WriteFileAtomically(run.Path("heldout/heldout.json"), result.dump(1) + "\n");
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

}  // namespace

namespace {

// Frames per second of the stages together (0 when they took no time).
double FramesPerSecond(const AdaptRun& run, std::initializer_list<const char*> stages) {
  double seconds = 0;
  for (const char* stage : stages) seconds += run.progress.value(stage, 0.0);
  return seconds > 0 ? run.frames.size() / seconds : 0.0;
}


// What the network learned from, how long, and what it measures on held-out frames.
nlohmann::json ModelCard(const AdaptRun& run) {
  const nlohmann::json selection = ReadJsonFileStrict(run.Path("train/capture_labels.json"));
  const nlohmann::json summary = ReadIfExists(run.Path("summary.json"));
  const nlohmann::json detection = ReadIfExists(run.Path("detect.json"));
  const bool detected = detection.is_object() && detection.value("ran", false);
  nlohmann::json card = {
      {"format", "handlabel-adapt-card"},
      {"capture", run.o.capture_dir},
      {"cameras", run.num_cameras},
      {"frames", run.frames.size()},
      {"options", AdaptOptionsJson(run.o)},
      {"start_weights", run.o.weights},
      {"network", run.Path("network.pt")},
      {"training_frames", run.train.size()},
      {"training_frames_with_fit_label", selection["training_frames"]},
      {"training_labels_kept", selection["kept"]},
      {"selection_rule", selection["rule"]},
      {"heldout_frames",
       run.heldout.empty() ? nlohmann::json()
                           : nlohmann::json{run.heldout.front(), run.heldout.back()}},
      {"plan", ReadJsonFileStrict(run.Path("train/plan.json"))},
      {"export", ReadIfExists(run.Path("export.json"))},
      {"heldout", ReadIfExists(run.Path("heldout/heldout.json"))},
      {"labels_by_path",
       summary.is_object() ? summary.value("by_path", nlohmann::json()) : nlohmann::json()},
      // The label stage reuses the detections: the detector's time is not in it.
      {"detection", detection},
      {"frames_per_second",
       {{"detect", detected ? FramesPerSecond(run, {"detect"}) : 0.0},
        {"fit_only", FramesPerSecond(run, {"fit"})},
        {"detect_and_fit", detected ? FramesPerSecond(run, {"detect", "fit"}) : 0.0},
        {"network_checks_fallback", FramesPerSecond(run, {"label"})}}},
      {"seconds", run.progress},
      {"total_seconds", run.ElapsedSeconds()},
      {"version", GetBuildInfo().version}};
  return card;
}

// A number of the card for reading: 3 significant digits.
std::string Sig(const nlohmann::json& value) {
  if (!value.is_number()) return value.dump();
  std::ostringstream out;
  out.precision(3);
  out << value.get<double>();
  return out.str();
}

std::string HeldoutLine(const nlohmann::json& h, const std::string& name) {
  if (!h.contains(name)) return "";
  const nlohmann::json& r = h[name];
  return "| " + name + " | " + Sig(r["mpjpe_mm_vs_fit_labels"]) + " | " +
         Sig(r["mpvpe_mm_vs_fit_labels"]) + " | " + r["passed_every_check"].dump() +
         " of " + r["frames"].dump() + " |\n";
}

std::string ModelCardMarkdown(const nlohmann::json& card) {
  std::ostringstream md;
  const nlohmann::json& plan = card["plan"];
  md << "# Adapted network: " << card["network"].get<std::string>() << "\n\n"
     << "Started from " << card["start_weights"].get<std::string>() << ", trained "
     << plan["steps"] << " steps (" << Sig(plan["seconds_per_step"]) << " s/step on "
     << plan["threads"] << " threads of " << plan["cpu"].get<std::string>() << ") on "
     << card["training_labels_kept"] << " of " << card["training_frames"] << " ("
     << card["training_frames_with_fit_label"] << " with a fit label)"
     << " training frames of " << card["capture"].get<std::string>() << " ("
     << card["cameras"] << " cameras), their fit labels kept by the rule: "
     << card["selection_rule"].get<std::string>() << ".\n\n";
  if (card["heldout"].is_object()) {
    md << "Held-out frames " << card["heldout_frames"][0].get<std::string>() << " to "
       << card["heldout_frames"][1].get<std::string>()
       << " (never trained on), the network alone against their fit labels:\n\n"
       << "| weights | MPJPE mm | MPVPE mm | passed every check |\n|---|---|---|---|\n"
       << HeldoutLine(card["heldout"], "before") << HeldoutLine(card["heldout"], "after")
       << "\n";
  }
  if (card["heldout"].is_object() && card["heldout"].contains("thresholds")) {
    const nlohmann::json& t = card["heldout"]["thresholds"];
    md << "Quality-check thresholds chosen on the adapted answers (bad: farther than "
       << Sig(t["accept_mm"]) << " mm from the fit label; " << t["bad_answers"]
       << " of " << t["bad_answers"].get<int>() + t["good_answers"].get<int>()
       << " are): the joint decision's Youden's J " << Sig(t["youden_current"]) << " -> "
       << Sig(t["youden_chosen"]) << ", answers kept " << t["kept_current"] << " ("
       << t["kept_bad_current"] << " bad) -> " << t["kept_chosen"] << " ("
       << t["kept_bad_chosen"] << " bad).\n\n| check | current | chosen |\n|---|---|---|\n";
    for (const nlohmann::json& c : t["checks"]) {
      md << "| " << c["check"].get<std::string>() << " | " << Sig(c["current"]) << " | "
         << Sig(c["chosen"]) << " |\n";
    }
    md << "\nIn a label job with this network:\n\n```\nrefine: "
       << "{max_reprojection_px: " << Sig(t["refine"]["max_reprojection_px"])
       << ", max_view_disagreement_mm: " << Sig(t["refine"]["max_view_disagreement_mm"])
       << ", max_detector_rms_px: " << Sig(t["refine"]["max_detector_rms_px"])
       << "}\n```\n\n";
  }
  md << "Labels (network + checks + fallback fit): " << card["labels_by_path"].dump()
     << ".\n\nFrames per second: detector " << Sig(card["frames_per_second"]["detect"])
     << " (0: the capture had detections), fit only "
     << Sig(card["frames_per_second"]["fit_only"])
     << ", network + checks + fallback on the same detections "
     << Sig(card["frames_per_second"]["network_checks_fallback"])
     << ".\n\nSeconds per stage:";
  for (const auto& [stage, seconds] : card["seconds"].items()) {
    md << " " << stage << " " << Sig(seconds);
  }
  md << "; total " << Sig(card["total_seconds"]) << " (" << Sig(card["total_seconds"].get<double>() / 60)
     << " min).\n";
  return md.str();
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
  for (int f = 0; f < capture.num_frames(); ++f) run.frames.push_back(capture.frame_id(f));
  std::sort(run.frames.begin(), run.frames.end());
  SplitFrames(&run);
  return run;
}

}  // namespace

void AdaptOptions::Check(const std::string& source) const {
  if (capture_dir.empty()) throw InputError(source, "--capture", "a capture folder", "empty");
  if (out_dir.empty()) throw InputError(source, "--out", "an output folder", "empty");
  RequireGreater(source, "--budget", budget_minutes, 0);
  RequireAtLeast(source, "--threads", threads, 1);
  RequireGreater(source, "--learning-rate", learning_rate, 0);
  RequireGreater(source, "--accept-mm", accept_mm, 0);
  selection.Check(source);
}

nlohmann::json AdaptOptionsJson(const AdaptOptions& o) {
  return {{"capture", o.capture_dir},        {"weights", o.weights},
          {"heldout", o.heldout},            {"label_min_views", o.selection.min_views},
          {"label_max_rms_px", o.selection.max_view_rms_px},
          {"learning_rate", o.learning_rate}, {"seed", o.seed},
          {"accept_mm", o.accept_mm}};
}

AdaptSummary RunAdaptation(const AdaptOptions& options, std::ostream* log) {
  AdaptRun run = PrepareRun(options, log);
  ClaimFolder(run);
  LoadProgress(&run);
  run.Say(std::to_string(run.frames.size()) + " frames, " + std::to_string(run.train.size()) +
          " to train on, " + std::to_string(run.heldout.size()) + " held out; budget " +
          FormatNumber(run.o.budget_minutes) + " min");
  RunStage(&run, "detect", [&] { DetectStage(run); });
  RunStage(&run, "fit", [&] { FitStage(run); });
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
  return summary;
}

}  // namespace handlabel
