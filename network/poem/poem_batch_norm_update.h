#pragma once
// Batch-norm statistics recomputed for given weights. Internal to network/ (includes
// LibTorch).
//
// The running means and variances of a checkpoint belong to the weights they were
// tracked under. Averaged weights (AveragePoemCheckpoints) have their own activation
// statistics, which the mean of the checkpoints' statistics only approximates; SWA's
// remedy is to measure them again with a pass over training data.

#include <torch/torch.h>

#include "network/poem/poem_model.h"
#include "network/poem/training_sample.h"

namespace handlabel {

// Resets the running statistics of every trainable BatchNorm2d and re-estimates them as
// the plain average over batches of samples [0, samples) of `source` (forward passes in
// training mode, no gradients); frozen batch norms keep theirs. The model is left in
// eval mode; no parameter changes. Returns the number of batch norms updated.
int RecomputePoemBatchNorm(PoemModel& model, const TrainingSampleSource& source,
                           int samples, int batch_size);

}  // namespace handlabel
