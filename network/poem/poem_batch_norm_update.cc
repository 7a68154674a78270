#include "network/poem/poem_batch_norm_update.h"

#include <algorithm>
#include <vector>

#include "core/errors.h"
#include "network/poem/poem_training_batch.h"

namespace handlabel {

int RecomputePoemBatchNorm(PoemModel& model, const TrainingSampleSource& source,
                           int samples, int batch_size) {
  HL_CHECK(samples > 0 && batch_size > 0, "RecomputePoemBatchNorm needs samples");
  std::vector<torch::nn::BatchNorm2dImpl*> norms;
  for (const auto& m : model->modules(/*include_self=*/false)) {
    if (auto* bn = m->as<torch::nn::BatchNorm2d>()) norms.push_back(bn);
  }
  std::vector<c10::optional<double>> momentum;
  for (auto* bn : norms) {
    momentum.push_back(bn->options.momentum());
    bn->reset_running_stats();
    bn->options.momentum(c10::nullopt);  // cumulative average over the batches below
  }
  torch::NoGradGuard no_grad;
  model->train();
  for (int first = 0; first < samples; first += batch_size) {
    model->forward(ToPoemTrainingBatch(
                       SampleRange(source, first, std::min(samples, first + batch_size)))
                       .batch);
  }
  model->eval();
  for (size_t i = 0; i < norms.size(); ++i) norms[i]->options.momentum(momentum[i]);
  return static_cast<int>(norms.size());
}

}  // namespace handlabel
