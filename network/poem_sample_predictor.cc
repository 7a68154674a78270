#include "network/poem_sample_predictor.h"

#include "core/errors.h"
#include "network/poem_checkpoint.h"
#include "network/poem_training_batch.h"

namespace handlabel {

struct PoemSamplePredictor::Impl {
  PoemModel model{nullptr};
  PoemConfig config;
};

PoemSamplePredictor::PoemSamplePredictor(const std::string& weights_path, int threads)
    : impl_(std::make_unique<Impl>()) {
  if (threads < 1) {
    throw InputError("predictor", "threads", ">= 1", std::to_string(threads));
  }
  torch::set_num_threads(threads);
  impl_->model = LoadPoemCheckpoint(weights_path);
  impl_->model->eval();
  impl_->config = impl_->model->config();
}

PoemSamplePredictor::~PoemSamplePredictor() = default;

const PoemConfig& PoemSamplePredictor::config() const { return impl_->config; }

std::vector<PoemPrediction> PoemSamplePredictor::Predict(
    const std::vector<TrainingSample>& samples) {
  return PredictPoem(impl_->model, samples);
}

}  // namespace handlabel
