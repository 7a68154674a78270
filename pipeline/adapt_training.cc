#include "pipeline/adapt_run.h"

// `handlabel adapt`'s backgrounds, train and export stages (pipeline/adapt.h): the
// capture's selected frames train the starting weights for as many steps as the budget
// pays for; the export averages the low-learning-rate checkpoints and measures batch norm
// on the capture.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "capture/capture_look.h"
#include "capture/native_frame_source.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/json_util.h"
#include "core/stopwatch.h"
#include "core/text.h"
#include "image/image_file.h"
#include "network/poem/loss_plot.h"
#include "network/poem/poem_trainer.h"
#include "pipeline/capture_training_data.h"
#include "pipeline/label_record.h"
#include "pipeline/train_config.h"
#include "training/capture_training_samples.h"
#include "training/mixed_training_samples.h"
#include "training/sample_sheet.h"
#include "training/training_samples.h"

namespace handlabel {
namespace adapt {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

// Steps timed before the plan (the first 10 include the start-up).
constexpr int64_t kTimingSteps = 20;
// The averaged checkpoints: those of the last 30 % of the steps, where the rate is low.
constexpr double kDecayAt = 0.7;
constexpr int kMaxBatchNormSamples = 256;
constexpr int kSynthFrameReuse = 4;

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

// The capture's labelled frames as training and held-out samples, and the training
// samples: those frames mixed with synthetic ones in the capture's look.
struct AdaptSamples {
  CaptureTrainingData data;
  std::unique_ptr<CaptureTrainingSamples> capture_train, heldout, batch_norm;
  std::unique_ptr<SynthTrainingSamples> synth;
  std::unique_ptr<MixedTrainingSamples> mixed;
  const TrainingSampleSource* train = nullptr;  // one of the above
};

AdaptSamples LoadSamples(const AdaptRun& run, const TrainConfig& c,
                         const HandModel& hand) {
  AdaptSamples s;
  s.data = LoadCaptureTrainingData(TrainingInputs(run), hand.num_vertices());
  s.capture_train = std::make_unique<CaptureTrainingSamples>(
      *s.data.source, s.data.train, CaptureSampleOptionsFor(c, false));
  s.train = s.capture_train.get();
  if (run.o.synth_share > 0) {
    TrainingSampleOptions synth = c.samples;
    synth.crop_size = c.network.crop_size;
    synth.augment_seed = run.o.seed;
    // Each rendered frame gives several samples (fresh augmentation each): rendering
    // a frame of every camera costs more than a training step's share of it.
    synth.frame_reuse = kSynthFrameReuse;
    // Views missed as often as the capture's detections miss them, so that the
    // synthetic samples also teach whole-image views at weight 0.
    synth.view_dropout = s.capture_train->MissedViewShare();
    s.synth = CaptureLookSynthSamples(run, *s.data.source, hand, s.data.train, synth);
    s.mixed = std::make_unique<MixedTrainingSamples>(*s.capture_train, *s.synth,
                                                     1.0 - run.o.synth_share, run.o.seed);
    s.train = s.mixed.get();
  }
  // Batch-norm statistics are measured on the training frames as inference crops them.
  s.batch_norm = std::make_unique<CaptureTrainingSamples>(
      *s.data.source, s.data.train, CaptureSampleOptionsFor(c, true));
  if (!s.data.validation.empty()) {
    s.heldout = std::make_unique<CaptureTrainingSamples>(
        *s.data.source, s.data.validation, CaptureSampleOptionsFor(c, true));
  }
  return s;
}

// train/samples.jpg: the first training samples of each source as the network sees
// them, their targets drawn (training/sample_sheet.h).
void WriteSampleSheet(const AdaptRun& run, const AdaptSamples& s) {
  constexpr int kRowsPerSource = 4;
  std::vector<TrainingSample> rows;
  int from_capture = 0, synthetic = 0;
  for (int64_t i = 0; i < 200 && (from_capture < kRowsPerSource ||
                                  (s.mixed && synthetic < kRowsPerSource));
       ++i) {
    const bool capture = !s.mixed || s.mixed->FromFirst(i);
    int& count = capture ? from_capture : synthetic;
    if (count >= kRowsPerSource) continue;
    ++count;
    rows.push_back(s.train->Sample(i));
  }
  WriteJpeg(run.Path("train/samples.jpg"), MakeTrainingSampleSheet(rows));
}

PoemTrainSummary TrainUntil(const AdaptRun& run, const TrainConfig& c,
                            const HandModel& hand, const AdaptSamples& s,
                            int64_t stop_at) {
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

// The checkpoints of the last 30 % of the steps (the latest one if none).
std::vector<std::string> AveragedCheckpoints(const std::string& train_dir,
                                             int64_t steps) {
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

// Frames the backgrounds' median is taken over: enough that a hand which stays a while
// somewhere still leaves most of them free there; few enough to read in seconds.
constexpr size_t kBackgroundFrames = 30;

std::string BackgroundPath(const AdaptRun& run, const std::string& camera) {
  return run.Path("backgrounds/" + camera + ".png");
}

// `count` frames spread evenly over `frames` (all of them when there are fewer).
std::vector<std::string> SpreadFrames(const std::vector<std::string>& frames,
                                      size_t count) {
  if (frames.size() <= count) return frames;
  std::vector<std::string> chosen;
  for (size_t i = 0; i < count; ++i) chosen.push_back(frames[i * frames.size() / count]);
  return chosen;
}

}  // namespace

void BackgroundsStage(const AdaptRun& run) {
  const std::vector<std::string> frames =
      SpreadFrames(WithFitLabel(run, run.frames), kBackgroundFrames);
  if (frames.empty()) {
    throw InputError(
        run.Path("fit/labels"), "labels",
        "fit labels of some frames (to leave the hand out of the backgrounds)", "none");
  }
  std::vector<Points3d> hands;
  for (const std::string& id : frames) {
    hands.push_back(ReadLabelFile(LabelFilePath(run.Path("fit"), id)).mesh.keypoints);
  }
  Rig rig;
  const std::vector<ImageU8> backgrounds =
      EmptySceneBackgrounds(NativeFrameSource(run.o.capture_dir), frames, hands, &rig);
  for (size_t c = 0; c < rig.size(); ++c) {
    WritePng(BackgroundPath(run, rig[c].name), backgrounds[c]);
  }
  run.Say("backgrounds: the median of " + std::to_string(frames.size()) +
          " frames per camera, the labelled hand left out (" + run.Path("backgrounds") +
          ")");
}

std::unique_ptr<SynthTrainingSamples> CaptureLookSynthSamples(
    const AdaptRun& run, const FrameSource& capture, const HandModel& hand,
    const std::vector<LabeledFrame>& labels, const TrainingSampleOptions& samples) {
  const Rig rig = PinholeRig(capture.Load(labels.front().id).rig);
  auto photos = std::make_shared<std::vector<ImageU8>>();
  for (const RigCamera& c : rig.cameras()) {
    photos->push_back(ReadPng(BackgroundPath(run, c.name)));
  }
  std::vector<Points3d> hands;
  for (const LabeledFrame& f : labels) hands.push_back(f.keypoints_3d);
  return std::make_unique<SynthTrainingSamples>(
      hand, rig, CaptureLookSynthOptions(rig, hands, photos, run.o.seed), samples);
}

namespace {

// The plan's checks so far: `checks` (an older run's single `replanned` counts as one).
nlohmann::json PlanChecks(const nlohmann::json& plan) {
  if (plan.contains("checks")) return plan["checks"];
  if (plan.contains("replanned")) return nlohmann::json::array({plan["replanned"]});
  return nlohmann::json::array();
}

}  // namespace

int64_t NextPlanCheck(const nlohmann::json& plan, int64_t step) {
  const int64_t steps = plan["steps"].get<int64_t>();
  const int64_t interval = std::max<int64_t>(5 * kTimingSteps, steps / 10);
  const nlohmann::json checks = PlanChecks(plan);
  int64_t next =
      (checks.empty() ? kTimingSteps : checks.back()["at_step"].get<int64_t>()) +
      interval;
  // A continued run past a check, or too near one to measure its speed: the next.
  while (next < step + interval / 2) next += interval;
  return next <= kDecayAt * steps ? next : 0;
}

void Replan(int64_t step, double seconds_per_step, double seconds, nlohmann::json* plan) {
  nlohmann::json checks = PlanChecks(*plan);
  const double spent = (checks.empty() ? (*plan)["seconds_before_training"]
                                       : checks.back()["seconds_spent"])
                           .get<double>() +
                       seconds;
  const double left = (*plan)["budget_seconds"].get<double>() - spent -
                      (*plan)["reserve_seconds"].get<double>();
  const int64_t extra =
      left > 0 ? static_cast<int64_t>(0.95 * left / seconds_per_step) : kTimingSteps;
  if (!plan->contains("first_plan_steps")) (*plan)["first_plan_steps"] = (*plan)["steps"];
  (*plan)["steps"] = step + std::max<int64_t>(extra, kTimingSteps);
  checks.push_back({{"at_step", step},
                    {"seconds_per_step", seconds_per_step},
                    {"seconds_spent", spent},
                    {"steps", (*plan)["steps"]}});
  (*plan)["checks"] = checks;
  plan->erase("replanned");
}

namespace {

// Trains to the end of the plan, checking it on the way (NextPlanCheck): each check
// plans the rest on the seconds per step since the previous one, so other work that
// arrives on the machine mid-run shortens the training instead of overrunning the budget.
void TrainChecked(AdaptRun* run, TrainConfig* c, const HandModel& hand,
                  const AdaptSamples& samples, const std::string& plan_path,
                  nlohmann::json* plan) {
  int64_t from =
      std::max<int64_t>(kTimingSteps, LatestPoemCheckpointStep(c->trainer.out_dir));
  for (int64_t at = NextPlanCheck(*plan, from); at > 0; at = NextPlanCheck(*plan, from)) {
    const Clock::time_point t0 = Clock::now();
    TrainUntil(*run, *c, hand, samples, at);
    const double seconds = SecondsSince(t0);
    const int64_t steps_before = (*plan)["steps"].get<int64_t>();
    Replan(at, seconds / static_cast<double>(at - from), seconds, plan);
    WriteFileAtomically(plan_path, plan->dump(1) + "\n");
    run->Say("train: steps " + std::to_string(from) + "-" + std::to_string(at) +
             " took " +
             FormatNumber((*plan)["checks"].back()["seconds_per_step"].get<double>()) +
             " s/step: " + (*plan)["steps"].dump() + " steps in all (planned " +
             std::to_string(steps_before) + ")");
    ApplyPlan(*plan, c);
    from = at;
  }
  TrainUntil(*run, *c, hand, samples, -1);
}

}  // namespace

void TrainStage(AdaptRun* run) {
  TrainConfig c = AdaptTrainConfig(*run);
  std::string hand_source;
  const HandModel hand = LoadTrainingHandModel(c, &hand_source);
  const AdaptSamples samples = LoadSamples(*run, c, hand);
  WriteFileAtomically(
      run->Path("train/capture_labels.json"),
      LabelSelectionJson(run->o.selection, samples.data.selection).dump(1) + "\n");
  run->Say("train: " + std::to_string(samples.data.train.size()) + " of " +
           std::to_string(run->train.size()) + " training frames kept (" +
           std::to_string(run->train.size() - samples.data.selection.size()) +
           " without a fit label; train/capture_labels.json), " +
           std::to_string(samples.data.validation.size()) + " of " +
           std::to_string(run->heldout.size()) + " held-out frames with a fit label");
  if (samples.synth) {
    run->Say(
        "train: a share of " + FormatNumber(run->o.synth_share) +
        " synthetic hands in the capture's look, " +
        std::to_string(std::lround(100 * samples.synth->options().view_dropout)) +
        " % of their views cut as missed detections (as the capture's detections miss "
        "on its training frames)");
  }
  WriteSampleSheet(*run, samples);
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
  nlohmann::json plan = ReadJsonFileStrict(plan_path);
  run->Say("train: " + plan["steps"].dump() + " steps planned at " +
           FormatNumber(plan["seconds_per_step"].get<double>()) + " s/step (" +
           plan_path + ")");
  ApplyPlan(plan, &c);
  TrainChecked(run, &c, hand, samples, plan_path, &plan);
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
  const int bn_samples = std::min<int>(kMaxBatchNormSamples,
                                       4 * static_cast<int>(samples.data.train.size())) /
                         batch * batch;
  ExportPoemCheckpointAverageAsHalf(paths, run.Path("network.pt"),
                                    samples.batch_norm.get(), bn_samples, batch);
  nlohmann::json names = nlohmann::json::array();
  for (const std::string& p : paths) names.push_back(fs::path(p).filename().string());
  WriteFileAtomically(
      run.Path("export.json"),
      nlohmann::json{{"averaged_checkpoints", names}, {"batch_norm_samples", bn_samples}}
              .dump(1) +
          "\n");
}

}  // namespace adapt
}  // namespace handlabel
