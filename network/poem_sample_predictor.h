#pragma once
// Runs a POEM checkpoint on training-style samples (crops with intrinsics and
// extrinsics already made), for validation and `handlabel eval-network`. Torch-free
// interface: the model lives behind the pimpl.

#include <memory>
#include <string>
#include <vector>

#include "network/poem_config.h"
#include "network/training_sample.h"

namespace handlabel {

class PoemSamplePredictor {
 public:
  // Loads an own POEM checkpoint (float32 or float16 storage). Throws InputError naming
  // the file if it is not one. `threads` LibTorch intra-op threads (>= 1).
  explicit PoemSamplePredictor(const std::string& weights_path, int threads = 1);
  ~PoemSamplePredictor();
  const PoemConfig& config() const;
  // One forward pass over all samples (a batch); eval mode, no gradients.
  std::vector<PoemPrediction> Predict(const std::vector<TrainingSample>& samples);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace handlabel
