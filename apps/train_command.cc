// `handlabel train`: trains POEM on synthetic captures made on the fly, or on a
// capture's own labelled frames (docs/training.md).

#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "capture/synth_capture.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "formats/sha256.h"
#include "network/poem/loss_plot.h"
#include "network/poem/poem_trainer.h"
#include "pipeline/capture_training_data.h"
#include "pipeline/train_config.h"
#include "training/capture_training_samples.h"
#include "training/mixed_training_samples.h"
#include "training/training_samples.h"

namespace handlabel {

namespace {

// The command line of `handlabel train`.
struct TrainFlags {
  std::string config_path, out_dir, init_weights, export_path;
  bool resume = false;
  int64_t steps = 0, stop_at = -1, init_step = 0;
  int threads = 0;
  double learning_rate = 0;
  std::vector<std::string> average;
  int bn_samples = 0;
  CaptureTrainingInputs capture;  // --capture, --labels, --train-frames, --val-frames
  double real_share = 1;          // --real-share
};

// Training on a capture's own labels (docs/training.md).
void AddCaptureOptions(CLI::App* app, TrainFlags* f) {
  CaptureTrainingInputs& c = f->capture;
  auto* capture = app->add_option(
      "--capture", c.capture_dir,
      "train on this native capture's labelled frames instead of synthetic ones "
      "(crops from its detections/ as inference crops them)");
  auto* labels =
      app->add_option("--labels", c.labels_dir,
                      "with --capture: the folder of its <frame>.json labels (a label "
                      "or fit job's labels/), the training targets");
  capture->needs(labels);
  labels->needs(capture);
  app->add_option("--train-frames", c.train_frames,
                  "with --capture: frames to train on, 'a:b' (positions in the sorted "
                  "frames, b excluded), 'id,id,...' or 'all' (default: every frame not "
                  "in --val-frames)")
      ->needs(capture);
  app->add_option("--val-frames", c.val_frames,
                  "with --capture: held-out frames to validate on (at the start and "
                  "every train.validate_every steps) instead of synthetic ones; same "
                  "forms as --train-frames")
      ->needs(capture);
  app->add_option("--label-min-views", c.selection.min_views,
                  "with --capture: a fit label trains only if at least this many views "
                  "fit its 2D within --label-max-rms-px (default 3)")
      ->needs(capture);
  app->add_option("--label-max-rms-px", c.selection.max_view_rms_px,
                  "with --capture: ... within this RMS pixel distance (fit.view_rms_px; "
                  "default 10); network labels train only if they passed every check")
      ->needs(capture);
  app->add_option("--real-share", f->real_share,
                  "with --capture: share of training samples from the capture; the rest "
                  "are the config's synthetic samples (default 1: all real)")
      ->needs(capture)
      ->check(CLI::Range(0.0, 1.0));
}

void AddTrainOptions(CLI::App* app, TrainFlags* f) {
  app->add_option("--config", f->config_path, "training config (YAML)")->required();
  app->add_flag("--resume", f->resume,
                "continue the run in the output folder from its latest checkpoint");
  app->add_option("--steps", f->steps, "total steps of the run (overrides train.steps)");
  app->add_option("--stop-at", f->stop_at,
                  "stop (with a checkpoint) once this step is reached; the schedule "
                  "still follows the total steps");
  app->add_option("--learning-rate", f->learning_rate,
                  "peak learning rate (overrides train.learning_rate); with --resume the "
                  "schedule changes from the checkpoint on, the Adam state is kept")
      ->check(CLI::Validator(
          [](std::string& value) {
            return std::strtod(value.c_str(), nullptr) > 0 ? std::string()
                                                           : "must be > 0, got " + value;
          },
          "> 0"));
  app->add_option("--out", f->out_dir, "run folder (overrides train.out_dir)");
  app->add_option("--threads", f->threads, "LibTorch threads (overrides train.threads)");
  app->add_option("--init-weights", f->init_weights,
                  "start a new run from these weights (optimizer state starts afresh)");
  app->add_option("--init-step", f->init_step,
                  "with --init-weights: the step those weights were saved at");
  auto* export_option = app->add_option(
      "--export", f->export_path,
      "do not train: write the latest checkpoint's weights of the run folder "
      "with float16 storage to this file (about half the size) and exit");
  app->add_option("--average", f->average,
                  "with --export: write the mean of these checkpoints' weights instead "
                  "of the latest (one config; e.g. the checkpoints kept by "
                  "train.keep_every during a constant-learning-rate phase)")
      ->needs(export_option);
  app->add_option("--bn-samples", f->bn_samples,
                  "with --average: measure the mean's batch-norm statistics again on "
                  "this many training samples of the config's data, or with --capture "
                  "of the capture's training frames as inference crops them (SWA's "
                  "batch-norm update), instead of averaging the checkpoints' "
                  "statistics; 0 = average them")
      ->needs("--average")
      ->check(CLI::NonNegativeNumber);
  AddCaptureOptions(app, f);
}

// The config file with the command line's overrides, checked.
TrainConfig LoadConfigWithOverrides(const TrainFlags& f) {
  TrainConfig config = LoadTrainConfig(f.config_path);
  if (f.steps > 0) config.trainer.steps = f.steps;
  if (!f.out_dir.empty()) config.trainer.out_dir = f.out_dir;
  if (f.threads > 0) config.trainer.threads = f.threads;
  if (f.learning_rate > 0) config.trainer.learning_rate = f.learning_rate;
  if (!f.init_weights.empty()) {
    config.trainer.init_weights = f.init_weights;
    config.trainer.init_step = f.init_step;
  }
  if (config.trainer.out_dir.empty()) {
    throw InputError(f.config_path, "train.out_dir", "a run folder (or --out)", "empty");
  }
  config.trainer.Check(f.config_path);
  return config;
}

// --export with --average: the mean of the checkpoints, batch-norm statistics averaged
// or measured again on training samples.
void ExportAverage(const TrainConfig& config, const TrainFlags& f) {
  if (f.bn_samples == 0) {
    ExportPoemCheckpointAverageAsHalf(f.average, f.export_path);
  } else if (!f.capture.capture_dir.empty()) {
    // With --capture: on the capture's training frames, cropped as inference crops
    // them (no augmentation), the domain the weights will label.
    std::string hand_source;
    const HandModel hand = LoadTrainingHandModel(config, &hand_source);
    const CaptureTrainingData data =
        LoadCaptureTrainingData(f.capture, hand.num_vertices());
    const CaptureTrainingSamples train(*data.source, data.train,
                                       CaptureSampleOptionsFor(config, true));
    ExportPoemCheckpointAverageAsHalf(f.average, f.export_path, &train, f.bn_samples,
                                      config.trainer.batch_size);
  } else {
    std::string hand_source;
    const HandModel hand = LoadTrainingHandModel(config, &hand_source);
    const SynthTrainingSamples train(hand, config.synth, config.samples);
    ExportPoemCheckpointAverageAsHalf(f.average, f.export_path, &train, f.bn_samples,
                                      config.trainer.batch_size);
  }
  const std::string bn_data =
      f.capture.capture_dir.empty() ? " samples" : " samples of the capture's frames";
  std::cout << "wrote " << f.export_path << " (mean of " << f.average.size()
            << " checkpoints"
            << (f.bn_samples > 0 ? ", batch-norm statistics from " +
                                       std::to_string(f.bn_samples) + bn_data
                                 : std::string())
            << ", float16)\n";
}

// --export alone: the run's latest checkpoint.
void ExportLatest(const TrainConfig& config, const TrainFlags& f) {
  const std::string latest = LatestPoemCheckpointModel(config.trainer.out_dir);
  if (latest.empty()) {
    throw InputError(config.trainer.out_dir, "latest.json", "a run with a checkpoint",
                     "none");
  }
  ConvertPoemCheckpointToHalf(latest, f.export_path);
  std::cout << "wrote " << f.export_path << " (step "
            << LatestPoemCheckpointStep(config.trainer.out_dir) << ", float16)\n";
}

// The samples a run trains and validates on, and the sources behind them.
struct TrainingSources {
  std::unique_ptr<SynthTrainingSamples> synth_train, synth_validation;
  CaptureTrainingData capture;
  std::unique_ptr<CaptureTrainingSamples> real_train, real_validation;
  std::unique_ptr<MixedTrainingSamples> mixed;
  const TrainingSampleSource* train = nullptr;
  const TrainingSampleSource* validation = nullptr;
  // With a capture: what the run learns from, written beside its checkpoints
  // (capture_labels.json) once the trainer holds the run folder.
  std::optional<nlohmann::json> capture_labels;
};

// The capture's labelled frames (mixed with synthetic ones below --real-share 1) and,
// with --val-frames, its held-out frames for validation, measured at the start too.
void AddCaptureSources(const TrainConfig& config, const HandModel& hand,
                       const TrainFlags& f, TrainingSources* s,
                       PoemTrainerOptions* trainer) {
  if (!(f.real_share > 0)) {
    throw InputError("command line", "--real-share", "> 0 (0 trains on no real frame)",
                     std::to_string(f.real_share));
  }
  s->capture = LoadCaptureTrainingData(f.capture, hand.num_vertices());
  s->real_train = std::make_unique<CaptureTrainingSamples>(
      *s->capture.source, s->capture.train, CaptureSampleOptionsFor(config, false));
  s->train = s->real_train.get();
  if (f.real_share < 1) {
    s->synth_train =
        std::make_unique<SynthTrainingSamples>(hand, config.synth, config.samples);
    s->mixed = std::make_unique<MixedTrainingSamples>(*s->real_train, *s->synth_train,
                                                      f.real_share, config.synth.seed);
    s->train = s->mixed.get();
  }
  if (!s->capture.validation.empty()) {
    s->real_validation = std::make_unique<CaptureTrainingSamples>(
        *s->capture.source, s->capture.validation, CaptureSampleOptionsFor(config, true));
    s->validation = s->real_validation.get();
    // One sample per held-out frame (the first epoch visits each once).
    trainer->validation_samples = static_cast<int>(s->capture.validation.size());
    trainer->validate_at_start = true;
  }
  std::cerr << "handlabel train: " << s->capture.train.size() << " training ("
            << s->capture.selection.size() - s->capture.train.size()
            << " labels left out, capture_labels.json) and "
            << s->capture.validation.size() << " validation frames of "
            << s->capture.source->Describe() << ", real share " << f.real_share << "\n";
  s->capture_labels = LabelSelectionJson(f.capture.selection, s->capture.selection);
}

TrainingSources MakeTrainingSources(const TrainConfig& config, const HandModel& hand,
                                    const TrainFlags& f, PoemTrainerOptions* trainer) {
  TrainingSources s;
  if (!f.capture.capture_dir.empty()) {
    AddCaptureSources(config, hand, f, &s, trainer);
  } else {
    s.synth_train =
        std::make_unique<SynthTrainingSamples>(hand, config.synth, config.samples);
    s.train = s.synth_train.get();
  }
  if (!s.validation) {
    s.synth_validation = std::make_unique<SynthTrainingSamples>(
        hand, ValidationSynthOptions(config), ValidationSampleOptions(config));
    s.validation = s.synth_validation.get();
  }
  return s;
}

// "3 frames, 000000 to 000002, sha256 1f0c...": which frames, comparable in one value
// however many there are.
std::string FrameSetText(const std::vector<LabeledFrame>& frames) {
  if (frames.empty()) return "none";
  std::string ids;
  for (const LabeledFrame& frame : frames) ids += frame.id + "\n";
  return std::to_string(frames.size()) + " frames, " + frames.front().id + " to " +
         frames.back().id + ", sha256 " + Sha256Hex(ids).substr(0, 16);
}

// What decides the run's samples (PoemTrainerOptions::data_settings): a resume with
// other values is refused naming the setting. The crop size, masks and augmentation
// seed follow from the network and the synth seed (LoadTrainConfig); the checkpoint's
// own config guards the network. A capture's frames count as the frames chosen (the
// same frames however --train-frames spells them).
nlohmann::json TrainingDataSettings(const TrainConfig& config, const TrainFlags& f,
                                    const TrainingSources& sources) {
  const TrainingSampleOptions& s = config.samples;
  nlohmann::json data = {{"samples",
                          {{"box_scale", s.box_scale},
                           {"min_box_px", s.min_box_px},
                           {"frame_reuse", s.frame_reuse}}}};
  // Only when set, so that runs from before the field resume as they were.
  if (s.view_dropout > 0) data["samples"]["view_dropout"] = s.view_dropout;
  if (sources.synth_train) data["synth"] = SynthOptionsToJson(config.synth);
  if (!f.capture.capture_dir.empty()) {
    data["capture"] = {
        {"dir",
         std::filesystem::absolute(f.capture.capture_dir).lexically_normal().string()},
        {"labels",
         std::filesystem::absolute(f.capture.labels_dir).lexically_normal().string()},
        {"train_frames", FrameSetText(sources.capture.train)},
        {"validation_frames", FrameSetText(sources.capture.validation)},
        {"real_share", f.real_share}};
  }
  return data;
}

void Train(const TrainConfig& config, const TrainFlags& f) {
  std::string hand_source;
  const HandModel hand = LoadTrainingHandModel(config, &hand_source);
  std::cerr << "handlabel train: hand model " << hand_source << "\n";
  PoemTrainerOptions trainer_options = config.trainer;
  const TrainingSources sources = MakeTrainingSources(config, hand, f, &trainer_options);
  trainer_options.data_settings = TrainingDataSettings(config, f, sources);
  const std::string run = config.trainer.out_dir;
  PoemTrainerHooks hooks;
  hooks.progress = [](const std::string& line) { std::cout << line << std::endl; };
  hooks.logs_written = [run] { DrawTrainingCurves(run); };
  hooks.folder_locked = [&] {
    if (!sources.capture_labels) return;
    WriteFileAtomically((std::filesystem::path(run) / "capture_labels.json").string(),
                        sources.capture_labels->dump(1) + "\n");
  };
  PoemTrainer trainer(config.network, hand, *sources.train, sources.validation,
                      trainer_options, hooks);
  const PoemTrainSummary s = trainer.Run(f.resume, f.stop_at);
  std::cout << "trained steps " << s.start_step << " -> " << s.end_step << " in "
            << s.seconds << " s; last loss " << s.last_loss << "; weights "
            << LatestPoemCheckpointModel(run) << "\n";
}

}  // namespace

int RunTrain(int argc, char** argv) {
  CLI::App app(
      "Train the POEM network on synthetic multi-view captures generated on the fly, "
      "or on a capture's own labelled frames (--capture, --labels), with checkpoints, "
      "resume, loss curves (CSV + PNG) and validation on held-out frames "
      "(docs/training.md).\n"
      "Example: handlabel train --config jobs/train_poem_small.yaml --out runs/small",
      "train");
  TrainFlags flags;
  AddTrainOptions(&app, &flags);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("train", [&] {
    const TrainConfig config = LoadConfigWithOverrides(flags);
    if (!flags.export_path.empty() && !flags.average.empty()) {
      ExportAverage(config, flags);
    } else if (!flags.export_path.empty()) {
      ExportLatest(config, flags);
    } else {
      Train(config, flags);
    }
    return 0;
  });
}

}  // namespace handlabel
