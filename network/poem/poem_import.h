#pragma once
// Import of the released reference checkpoint `PtEmbedMultiviewStereo.pth.tar`
// (torch.save zip: data.pkl + raw storages; an OrderedDict of tensors) with the
// project's own zip and restricted pickle readers (formats/torch_archive.h). LibTorch's
// own pickle_load cannot read it. Internal to network/ (includes LibTorch).

#include <torch/torch.h>

#include <map>
#include <string>

#include "network/poem/poem_checkpoint.h"
#include "network/poem/poem_model.h"

namespace handlabel {

// Every tensor of a torch.save archive under its state_dict key, as float32 (int64 for
// integer tensors). A leading "state_dict." or "module." is removed.
std::map<std::string, torch::Tensor> ReadTorchStateDict(const std::string& path);

// The architecture a reference state_dict was built with, from its shapes: backbone
// and width, embed_dim, transformer_dim, depth_bins, num_decoder_blocks. Everything
// the weights do not determine (view count, crop size, sampled points, radius,
// neighbours, position range) is copied from `base`. Throws InputError naming
// `source` if a key POEM needs is missing.
PoemConfig InferPoemConfig(const std::map<std::string, torch::Tensor>& state,
                           const PoemConfig& base, const std::string& source);

// Reads the released checkpoint and loads it into a model built from `config`.
// Refuses (InputError listing every difference) a checkpoint whose sizes disagree with
// the config; MANO buffers (mano_layer.*) are ignored and reported. The view count is
// not stored in the weights: the caller's config must name the dataset the weights
// were trained for (ReleasedPoemConfig(PoemDataset)).
PoemModel ImportReleasedPoemCheckpoint(const std::string& path, const PoemConfig& config,
                                       StateDictReport* report = nullptr);

}  // namespace handlabel
