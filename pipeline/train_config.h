#pragma once
// A POEM training job, as read from its YAML file (jobs/train_poem_small.yaml; every
// field is described in docs/training.md). Missing keys keep the defaults below;
// unknown keys are errors. Relative paths are resolved against the current folder.

#include <cstdint>
#include <string>

#include "capture/synth_capture.h"
#include "hand/hand_model.h"
#include "network/poem/poem_config.h"
#include "network/poem/poem_trainer.h"
#include "training/training_samples.h"

namespace handlabel {

struct TrainConfig {
  std::string source_file;  // the YAML file (for error messages)
  // network: a PoemConfigByName name ("small", "tiny", "released-dexycb", ...), then
  // per-field overrides in network_overrides (PoemConfig JSON field names).
  std::string network_name = "small";
  PoemConfig network = SmallPoemConfig(8);
  // Hand model file or "capsule"; empty = $HANDLABEL_HAND_MODEL, else the shipped open
  // hand (models/open_hand_right.npz).
  std::string hand_model;
  // Synthetic training data (data.*): rig preset, seed, scene and backgrounds.
  SynthCaptureOptions synth;
  // Seed of the held-out validation data (a different stream of scenes).
  uint64_t validation_seed = 1000001;
  TrainingSampleOptions samples;  // crops, frame reuse, augmentation
  PoemTrainerOptions trainer;     // optimisation, checkpoints, validation, out_dir
};

// Throws InputError naming the file and field on bad content.
TrainConfig LoadTrainConfig(const std::string& path);

// The hand model of a config, chosen by ResolveHandModel (pipeline/hand_model_source.h):
// `hand_model` if set (a file trains with its own side), else $HANDLABEL_HAND_MODEL,
// else the shipped models/open_hand_right.npz of the data folder, else the open hand
// built in memory from its default design (what the shipped file holds). `source`
// receives where it came from.
HandModel LoadTrainingHandModel(const TrainConfig& config, std::string* source);

// The validation data of a config: same rig and scene settings, validation_seed, no
// augmentation, no frame reuse.
SynthCaptureOptions ValidationSynthOptions(const TrainConfig& config);
TrainingSampleOptions ValidationSampleOptions(const TrainConfig& config);

}  // namespace handlabel
