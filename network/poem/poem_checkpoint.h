#pragma once
// POEM weights on disk. Internal to network/ (includes LibTorch).
//
// Own checkpoints: a LibTorch archive holding the state_dict (reference key names) and
// the PoemConfig as JSON, so a checkpoint rebuilds its own model.
// The released `PtEmbedMultiviewStereo.pth.tar` is imported by poem_import.h.

#include <torch/torch.h>

#include <map>
#include <string>
#include <vector>

#include "network/poem/poem_model.h"

namespace handlabel {

// Every parameter and buffer of the model under its state_dict key.
std::map<std::string, torch::Tensor> PoemStateDict(PoemModel& model);

struct StateDictReport {
  std::vector<std::string> missing;     // model keys absent from the file
  std::vector<std::string> unexpected;  // file keys the model does not have
  std::vector<std::string> ignored;  // file keys dropped on purpose (e.g. mano_layer.*)
};

// Copies `tensors` into the model (converted to float32, or int64 for
// num_batches_tracked). Keys starting with one of `ignored_prefixes` are skipped and
// reported. Throws InputError naming `source` if a key is missing or unexpected or a
// shape differs, listing all of them, or if a tensor holds NaN or infinity.
StateDictReport LoadPoemStateDict(PoemModel& model,
                                  const std::map<std::string, torch::Tensor>& tensors,
                                  const std::string& source,
                                  const std::vector<std::string>& ignored_prefixes = {});

// Written atomically (SaveArchiveAtomically).
void SavePoemCheckpoint(PoemModel& model, const std::string& path);
// Serialises `archive` in memory, then writes it with WriteFileAtomically
// (core/atomic_file.h): a full disk is an Error naming `path` and leaves neither a
// partial file nor a temporary (LibTorch's own file writer aborted the process when its
// destructor failed to finish the file).
void SaveArchiveAtomically(torch::serialize::OutputArchive& archive,
                           const std::string& path);
// A LibTorch exception's message without its backtrace (c10::Error), else what().
std::string TorchErrorText(const std::exception& error);
// The config embedded in an own checkpoint. Throws InputError if the file is not one.
PoemConfig ReadPoemCheckpointConfig(const std::string& path);
// Builds the model from the embedded config and loads the weights.
PoemModel LoadPoemCheckpoint(const std::string& path);
// Loads into an existing model; throws InputError listing every config difference if
// the checkpoint was written for another configuration. With as_init_weights (weights
// a training run starts from) two differences are allowed:
// - the mask head: a checkpoint without one loads into a model with one (whose head
//   keeps its current weights: training a head onto trained weights), and a
//   checkpoint's head is dropped when the model has none (continuing the main training
//   from weights that carry a head);
// - the view count: no parameter's shape depends on it (views share the backbone and
//   are summed), so 8-view weights start a 5-view rig's run (`handlabel adapt`).
void LoadPoemCheckpointInto(PoemModel& model, const std::string& path,
                            bool as_init_weights = false);

// The element-wise mean of the weights and batch-norm statistics of checkpoints written
// for one config (num_batches_tracked: the last file's). The checkpoints of a
// constant-learning-rate phase wander around one basin; their mean lies nearer its
// middle. Throws InputError if the list is empty or a file was written for another
// config.
PoemModel AveragePoemCheckpoints(const std::vector<std::string>& paths);

}  // namespace handlabel
