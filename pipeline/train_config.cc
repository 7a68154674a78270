#include "pipeline/train_config.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "core/size_checks.h"
#include "pipeline/hand_model_source.h"
#include "pipeline/train_config_yaml.h"

namespace handlabel {
namespace {

// The named network for the rig's view count, then network_overrides on top.
void ResolveNetwork(const std::string& overrides_json, const std::string& path,
                    TrainConfig* c) {
  const int views = static_cast<int>(MakePresetRig(c->synth.rig, c->synth.seed).size());
  c->network = PoemConfigByName(c->network_name, views);
  if (!overrides_json.empty()) {
    nlohmann::json j = nlohmann::json::parse(c->network.ToJson());
    // A named object: items() of a temporary would dangle inside the loop.
    const nlohmann::json given = nlohmann::json::parse(overrides_json);
    for (const auto& [key, value] : given.items()) j[key] = value;
    c->network = PoemConfig::FromJson(j.dump(), path + " (network_overrides)");
  }
  if (c->network.num_views != views) {
    throw InputError(path, "network", std::to_string(views) + " views (the rig's)",
                     std::to_string(c->network.num_views));
  }
  if (c->trainer.mask_head_only && !c->network.mask_head) {
    throw InputError(path, "train.trainable",
                     "all (mask_head needs network_overrides: {mask_head: true})",
                     "mask_head");
  }
}

// train.batch_size, checked before anything is allocated: >= 1, and the batches in
// flight (the one trained and prefetch_batches made ahead) of input crops alone (float
// RGB per view; the network's activations take several times more) fit in memory. A
// batch size of 1e9 otherwise ran for minutes without a step.
void CheckBatchSize(const std::string& path, const TrainConfig& c) {
  const int batch = c.trainer.batch_size;
  if (batch < 1) {
    throw InputError(path, "train.batch_size", "an integer >= 1", std::to_string(batch));
  }
  const double crop = c.network.crop_size;
  const double sample_bytes = c.network.num_views * 3.0 * crop * crop * sizeof(float);
  const double memory = PhysicalMemoryBytes();
  const int in_flight = std::max(1, c.trainer.prefetch_batches + 1);
  const double largest = memory > 0 ? std::floor(memory / (sample_bytes * in_flight)) : 0;
  if (memory > 0 && batch > largest) {
    char detail[200];
    std::snprintf(
        detail, sizeof(detail),
        "a batch whose input crops fit in memory: at most %.0f samples (%d views "
        "of %d px take %.1f MB each, %d batch(es) in flight, %.1f GB of memory)",
        largest, c.network.num_views, c.network.crop_size, sample_bytes / 1e6, in_flight,
        memory / 1e9);
    throw InputError(path, "train.batch_size", detail, std::to_string(batch));
  }
}

// Sample options that follow from the network and trainer, then the final checks.
void DeriveSampleOptions(const std::string& path, TrainConfig* c) {
  c->samples.crop_size = c->network.crop_size;
  c->samples.masks = c->network.mask_head;  // the mask head's targets
  // Checked here, by its own name: it becomes the samples' internal reuse_group.
  CheckBatchSize(path, *c);
  c->samples.reuse_group = c->trainer.batch_size;
  c->samples.augment_seed = c->synth.seed;
  c->samples.Check(path);
  if (!c->trainer.out_dir.empty()) c->trainer.Check(path);
}

}  // namespace

TrainConfig LoadTrainConfig(const std::string& path) {
  TrainConfigFields fields = ReadTrainConfigYaml(path);
  TrainConfig& c = fields.config;
  c.synth.Check("synth options");
  ResolveNetwork(fields.network_overrides_json, path, &c);
  DeriveSampleOptions(path, &c);
  return c;
}

HandModel LoadTrainingHandModel(const TrainConfig& config, std::string* source) {
  // No side asked for: a given file trains with its own side.
  ResolvedHandModel r = ResolveHandModel(config.hand_model, std::nullopt,
                                         {config.source_file, "hand_model"});
  *source = r.source;
  return std::move(r.model);
}

SynthCaptureOptions ValidationSynthOptions(const TrainConfig& config) {
  SynthCaptureOptions o = config.synth;
  o.seed = config.validation_seed;
  return o;
}

TrainingSampleOptions ValidationSampleOptions(const TrainConfig& config) {
  TrainingSampleOptions o = config.samples;
  o.augment.enabled = false;
  o.frame_reuse = 1;
  o.reuse_group = 1;
  o.augment_seed = config.validation_seed;
  return o;
}

}  // namespace handlabel
