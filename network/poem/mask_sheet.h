#pragma once
// A picture of the mask head's answers (`handlabel eval-network --mask-png`): one row
// per sample, one tile per view, each the network's input crop with the predicted
// mask tinted red (cells with probability > 0.5) and the true mask's outline in green.

#include <vector>

#include "image/image.h"
#include "network/poem/training_sample.h"

namespace handlabel {

// `predictions[i]` belongs to `samples[i]`; samples need crop masks and predictions
// mask-head probabilities. Throws InputError if either is missing.
ImageU8 MakeMaskSheet(const std::vector<TrainingSample>& samples,
                      const std::vector<PoemPrediction>& predictions);

}  // namespace handlabel
