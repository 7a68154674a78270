#pragma once
// The POEM training loop: Adam with warm-up and a step decay, per-parameter gradient
// clipping (the reference recipe), batches made ahead by a producer thread, atomic
// checkpoints with resume, a progress line, loss curves as CSV and periodic
// validation (MPJPE / MPVPE) on a held-out sample source. docs/training.md.
//
// Determinism: sample i of step s is train.Sample(s * batch_size + i), the model starts
// from MakeRandomPoemModel(config, seed) and torch's generator is re-seeded from
// (seed, step) before every step, so a run resumed from a checkpoint continues exactly
// as the uninterrupted run would (same thread count).
//
// Output folder:
//   .handlabel.lock                   the running trainer's lock (core/file_lock.h)
//   latest.json                       which checkpoint to resume from (written last),
//                                     and the settings a resume must keep
//   checkpoints/step_XXXXXXXX.pt      model (an own POEM checkpoint, usable as weights)
//   checkpoints/step_XXXXXXXX.optim   optimizer state and step
//   loss.csv                          step, lr, total, every loss term, samples/s, wall s
//   validation.csv                    step, mpjpe_mm, mpvpe_mm, samples[, mask_iou]
// Torch-free interface (the model lives behind the pimpl), so apps/ and pipeline/ can
// drive training.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "hand/hand_model.h"
#include "network/poem/poem_config.h"
#include "network/poem/training_sample.h"

namespace handlabel {

struct PoemTrainerOptions {
  int64_t steps = 20000;        // optimisation steps in all (>= 1)
  int batch_size = 4;           // multi-view samples per step (>= 1)
  double learning_rate = 5e-4;  // Adam, after warm-up (> 0)
  int64_t warmup_steps = 200;   // linear ramp from 10 % of learning_rate (>= 0)
  // After decay_at * steps the rate is multiplied by decay_factor (the reference: x0.1
  // at epoch 70 of 100).
  double decay_at = 0.7;
  double decay_factor = 0.1;
  double grad_clip_norm = 1.0;     // per-parameter L2 clip (reference); 0 = off
  int64_t checkpoint_every = 200;  // steps between checkpoints (>= 1)
  int keep_checkpoints = 3;        // older checkpoints are deleted (>= 1)
  // Weights of checkpoints at multiples of keep_every are never deleted (their optimizer
  // state is): material for `train --export --average`. 0 = off.
  int64_t keep_every = 0;
  int64_t log_every = 10;         // steps between progress lines / CSV rows (>= 1)
  int64_t validate_every = 1000;  // steps between validations; 0 = never
  int validation_samples = 64;    // held-out samples per validation
  // Also validate before the first step of a new run (not of a resumed one), so that
  // validation.csv holds the starting weights' numbers (e.g. of init_weights before
  // fine-tuning).
  bool validate_at_start = false;
  uint64_t seed = 1;         // model initialisation and per-step torch seeds
  int threads = 1;           // LibTorch intra-op threads (>= 1)
  int prefetch_batches = 2;  // batches made ahead on a producer thread; 0 = inline
  std::string out_dir;       // run folder (created)
  // Start a new run (no checkpoint in out_dir yet) from these weights instead of random
  // ones, counting steps from init_step; the optimizer state starts afresh. Used to
  // continue from the small weights-only checkpoint committed to the repository.
  // init_weights may lack the mask head (the head then starts from random weights), or
  // have one the network has not (it is dropped).
  std::string init_weights;
  int64_t init_step = 0;
  // Train only the mask head (PoemConfig::mask_head) on frozen features, with the
  // mask loss alone; everything else keeps the init_weights bit for bit.
  bool mask_head_only = false;
  // Loss weights (PoemLossOptions; the reference's values).
  double heatmap_weight = 10.0;
  double triangulation_weight = 10.0;
  double joints_weight = 1.0;
  double vertices_weight = 1.0;
  double joints_2d_weight = 1.0;
  double mask_weight = 1.0;
  // What decides the training samples (the caller's data and sampling settings, e.g.
  // the synthetic data's seed, image size and objects), recorded in latest.json with
  // batch_size and seed. A resume with other values of any of them is an InputError
  // naming the first that differs: the run would go on silently on other data. Empty:
  // not recorded, not checked.
  nlohmann::json data_settings = nlohmann::json::object();
  void Check(const std::string& source) const;
};

// The learning rate at a step.
double PoemLearningRate(const PoemTrainerOptions& options, int64_t step);

struct PoemValidation {
  int64_t step = 0;
  double mpjpe_mm = 0;
  double mpvpe_mm = 0;
  int samples = 0;
  double mask_iou = -1;  // -1: the model has no mask head
};

struct PoemTrainerHooks {
  // Each progress line (also printed nowhere else); may be empty.
  std::function<void(const std::string&)> progress;
  // Called after loss.csv / validation.csv were extended (e.g. to redraw a plot).
  std::function<void()> logs_written;
  // Called once Run holds the run folder, before it writes anything there: where a
  // caller writes its own files of the run (e.g. which labels it learned from).
  std::function<void()> folder_locked;
};

struct PoemTrainSummary {
  int64_t start_step = 0;  // 0, or the checkpoint step resumed from
  int64_t end_step = 0;    // steps done when Run returned
  double seconds = 0;
  double last_loss = 0;
  PoemValidation last_validation;
};

class PoemTrainer {
 public:
  // `hand_model` gives the keypoint regressor of the loss; its vertex count must be
  // the network's. `validation` may be null.
  PoemTrainer(const PoemConfig& config, const HandModel& hand_model,
              const TrainingSampleSource& train, const TrainingSampleSource* validation,
              const PoemTrainerOptions& options, PoemTrainerHooks hooks = {});
  ~PoemTrainer();

  // Trains until options.steps, or until `stop_at_step` (>= 0) if that comes first,
  // writing a checkpoint at the end. With `resume`, continues from latest.json if the
  // folder has one; without it, a folder that already holds a run is an InputError.
  // One writer per run folder: holds its lock (core/file_lock.h) throughout; a second
  // run on the folder meanwhile is an InputError naming the holder.
  PoemTrainSummary Run(bool resume, int64_t stop_at_step = -1);

  // Writes the current weights as an own POEM checkpoint (float16 storage if `half`).
  void SaveWeights(const std::string& path, bool half = false);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Step of the latest checkpoint in a run folder, or -1.
int64_t LatestPoemCheckpointStep(const std::string& out_dir);
// Model file of the latest checkpoint ("" if none).
std::string LatestPoemCheckpointModel(const std::string& out_dir);

// The POEM config embedded in an own POEM checkpoint (torch-free for apps/ and
// pipeline/). Throws InputError naming the file when it is not one.
PoemConfig PoemCheckpointConfig(const std::string& path);

// Writes the weights of an own POEM checkpoint for a rig of `num_views` cameras (no
// parameter depends on the view count; only the config changes), e.g. to measure
// 8-view weights on a 5-camera rig before adapting them. float16 storage.
void WritePoemCheckpointForViews(const std::string& in_path, int num_views,
                                 const std::string& out_path);

// Rewrites an own POEM checkpoint with float16 storage (about half the size; it loads
// with LoadPoemCheckpoint like any other, converted back to float32).
void ConvertPoemCheckpointToHalf(const std::string& in_path, const std::string& out_path);
// Writes the mean of checkpoints of one config (AveragePoemCheckpoints) with float16
// storage. With `bn_source`, the mean's batch-norm statistics are then measured again on
// its samples [0, bn_samples) in batches of `batch_size` (RecomputePoemBatchNorm)
// instead of being the checkpoints' averaged ones.
void ExportPoemCheckpointAverageAsHalf(const std::vector<std::string>& in_paths,
                                       const std::string& out_path,
                                       const TrainingSampleSource* bn_source = nullptr,
                                       int bn_samples = 0, int batch_size = 4);

}  // namespace handlabel
