// `handlabel train`: trains POEM on synthetic captures made on the fly
// (docs/training.md).

#include <cstdlib>
#include <iostream>
#include <string>
#include <vector>

#include "apps/cli_util.h"
#include "apps/commands.h"
#include "core/errors.h"
#include "network/poem_trainer.h"
#include "network/loss_plot.h"
#include "pipeline/train_config.h"
#include "pipeline/training_samples.h"

namespace handlabel {

int RunTrain(int argc, char** argv) {
  CLI::App app(
      "Train the POEM network on synthetic multi-view captures generated on the fly, "
      "with checkpoints, resume, loss curves (CSV + PNG) and validation on held-out "
      "synthetic frames (docs/training.md).\n"
      "Example: handlabel train --config jobs/train_poem_small.yaml --out runs/small",
      "train");
  std::string config_path, out_dir, init_weights, export_path;
  bool resume = false;
  int64_t steps = 0, stop_at = -1, init_step = 0;
  int threads = 0;
  double learning_rate = 0;
  app.add_option("--config", config_path, "training config (YAML)")->required();
  app.add_flag("--resume", resume,
               "continue the run in the output folder from its latest checkpoint");
  app.add_option("--steps", steps, "total steps of the run (overrides train.steps)");
  app.add_option("--stop-at", stop_at,
                 "stop (with a checkpoint) once this step is reached; the schedule "
                 "still follows the total steps");
  app.add_option("--learning-rate", learning_rate,
                 "peak learning rate (overrides train.learning_rate); with --resume the "
                 "schedule changes from the checkpoint on, the Adam state is kept")
      ->check(CLI::Validator(
          [](std::string& value) {
            return std::strtod(value.c_str(), nullptr) > 0 ? std::string()
                                                           : "must be > 0, got " + value;
          },
          "> 0"));
  app.add_option("--out", out_dir, "run folder (overrides train.out_dir)");
  app.add_option("--threads", threads, "LibTorch threads (overrides train.threads)");
  app.add_option("--init-weights", init_weights,
                 "start a new run from these weights (optimizer state starts afresh)");
  app.add_option("--init-step", init_step,
                 "with --init-weights: the step those weights were saved at");
  auto* export_option = app.add_option(
      "--export", export_path,
      "do not train: write the latest checkpoint's weights of the run folder "
      "with float16 storage to this file (about half the size) and exit");
  std::vector<std::string> average;
  app.add_option("--average", average,
                 "with --export: write the mean of these checkpoints' weights instead "
                 "of the latest (one config; e.g. the checkpoints kept by "
                 "train.keep_every during a constant-learning-rate phase)")
      ->needs(export_option);
  int bn_samples = 0;
  app.add_option("--bn-samples", bn_samples,
                 "with --average: measure the mean's batch-norm statistics again on this "
                 "many training samples of the config's data (SWA's batch-norm update) "
                 "instead of averaging the checkpoints' statistics; 0 = average them")
      ->needs("--average")
      ->check(CLI::NonNegativeNumber);
  if (const int status = ParseCommandLine(app, argc, argv); status >= 0) return status;
  return RunReportingErrors("train", [&] {
    TrainConfig config = LoadTrainConfig(config_path);
    if (steps > 0) config.trainer.steps = steps;
    if (!out_dir.empty()) config.trainer.out_dir = out_dir;
    if (threads > 0) config.trainer.threads = threads;
    if (learning_rate > 0) config.trainer.learning_rate = learning_rate;
    if (!init_weights.empty()) {
      config.trainer.init_weights = init_weights;
      config.trainer.init_step = init_step;
    }
    if (config.trainer.out_dir.empty()) {
      throw InputError(config_path, "train.out_dir", "a run folder (or --out)", "empty");
    }
    config.trainer.Check(config_path);
    if (!export_path.empty() && !average.empty()) {
      if (bn_samples == 0) {
        ExportPoemCheckpointAverageAsHalf(average, export_path);
      } else {
        std::string hand_source;
        const HandModel hand = LoadTrainingHandModel(config, &hand_source);
        const SynthTrainingSamples train(hand, config.synth, config.samples);
        ExportPoemCheckpointAverageAsHalf(average, export_path, &train, bn_samples,
                                          config.trainer.batch_size);
      }
      std::cout << "wrote " << export_path << " (mean of " << average.size()
                << " checkpoints"
                << (bn_samples > 0 ? ", batch-norm statistics from " +
                                         std::to_string(bn_samples) + " samples"
                                   : std::string())
                << ", float16)\n";
      return 0;
    }
    if (!export_path.empty()) {
      const std::string latest = LatestPoemCheckpointModel(config.trainer.out_dir);
      if (latest.empty()) {
        throw InputError(config.trainer.out_dir, "latest.json", "a run with a checkpoint",
                         "none");
      }
      ConvertPoemCheckpointToHalf(latest, export_path);
      std::cout << "wrote " << export_path << " (step "
                << LatestPoemCheckpointStep(config.trainer.out_dir) << ", float16)\n";
      return 0;
    }
    std::string hand_source;
    const HandModel hand = LoadTrainingHandModel(config, &hand_source);
    std::cerr << "handlabel train: hand model " << hand_source << "\n";
    const SynthTrainingSamples train(hand, config.synth, config.samples);
    const SynthTrainingSamples validation(hand, ValidationSynthOptions(config),
                                          ValidationSampleOptions(config));
    const std::string run = config.trainer.out_dir;
    PoemTrainerHooks hooks;
    hooks.progress = [](const std::string& line) { std::cout << line << std::endl; };
    hooks.logs_written = [run] { DrawTrainingCurves(run); };
    PoemTrainer trainer(config.network, hand, train, &validation, config.trainer, hooks);
    const PoemTrainSummary s = trainer.Run(resume, stop_at);
    std::cout << "trained steps " << s.start_step << " -> " << s.end_step << " in "
              << s.seconds << " s; last loss " << s.last_loss << "; weights "
              << LatestPoemCheckpointModel(run) << "\n";
    return 0;
  });
}

}  // namespace handlabel
