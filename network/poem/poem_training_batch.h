#pragma once
// Tensors from training samples, and predictions back to plain C++.
// Internal to network/ (includes LibTorch).

#include <torch/torch.h>

#include <vector>

#include "network/poem/poem_loss.h"
#include "network/poem/poem_model.h"
#include "network/poem/poem_trainer.h"
#include "network/poem/training_sample.h"

namespace handlabel {

struct PoemTrainingBatch {
  PoemBatch batch;
  PoemTargets targets;
};

// Stacks samples (all with the same view count and crop size) into float32 tensors.
PoemTrainingBatch ToPoemTrainingBatch(const std::vector<TrainingSample>& samples);

// Runs the model in eval mode without gradients, master frame of each sample.
std::vector<PoemPrediction> PredictPoem(PoemModel& model,
                                        const std::vector<TrainingSample>& samples);

}  // namespace handlabel

namespace handlabel {

// Mean errors over samples [0, count) of `source` (batches of `batch_size`).
PoemValidation ValidatePoem(PoemModel& model, const TrainingSampleSource& source,
                            int count, int batch_size);

}  // namespace handlabel
