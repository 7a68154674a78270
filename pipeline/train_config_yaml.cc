#include "pipeline/train_config_yaml.h"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "pipeline/yaml_section.h"

namespace handlabel {
namespace {

// Scalars of a YAML mapping as JSON numbers, booleans or strings; lists as arrays.
nlohmann::json ToJson(const YAML::Node& node) {
  if (node.IsSequence()) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& item : node) a.push_back(ToJson(item));
    return a;
  }
  if (node.IsMap()) {
    nlohmann::json o = nlohmann::json::object();
    for (const auto& e : node) o[e.first.as<std::string>()] = ToJson(e.second);
    return o;
  }
  const std::string text = node.as<std::string>();
  try {
    size_t used = 0;
    const long long i = std::stoll(text, &used);
    if (used == text.size()) return i;
  } catch (const std::exception&) {
  }
  try {
    size_t used = 0;
    const double d = std::stod(text, &used);
    if (used == text.size()) return d;
  } catch (const std::exception&) {
  }
  if (text == "true") return true;
  if (text == "false") return false;
  return text;
}

YAML::Node ReadYamlFile(const std::string& path) {
  if (!std::filesystem::exists(path)) {
    throw InputError(path, "", "an existing training config (YAML)", "no such file");
  }
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw InputError(path, "", "valid YAML", e.what());
  }
}

// data.*: the synthetic training data.
void ReadData(Section data, TrainConfig* c) {
  bool objects = c->synth.scene.objects, clutter = c->synth.view.background.clutter;
  data.Read("preset", &c->synth.rig.preset);
  data.Read("width", &c->synth.rig.width);
  data.Read("height", &c->synth.rig.height);
  data.Read("seed", &c->synth.seed);
  data.Read("validation_seed", &c->validation_seed);
  data.Read("objects", &objects);
  data.Read("max_objects", &c->synth.scene.max_objects);
  data.Read("object_probability", &c->synth.scene.object_probability);
  data.Read("clutter", &clutter);
  std::string appearance = SynthAppearanceName(c->synth.view.appearance);
  data.Read("appearance", &appearance);
  data.Read("frame_reuse", &c->samples.frame_reuse);
  data.Read("box_scale", &c->samples.box_scale);
  data.Read("view_dropout", &c->samples.view_dropout);
  data.Read("generator_threads", &c->synth.num_threads);
  data.RejectUnknownKeys();
  c->synth.scene.objects = objects;
  c->synth.view.background.clutter = clutter;
  c->synth.view.appearance =
      SynthAppearanceFromName(appearance, c->source_file, data.Name("appearance"));
}

// augment.*
void ReadAugment(Section aug, TrainingAugmentOptions* a) {
  aug.Read("enabled", &a->enabled);
  aug.Read("scale_sigma", &a->scale_sigma);
  aug.Read("rotation_probability", &a->rotation_probability);
  aug.Read("rotation_sigma_deg", &a->rotation_sigma_deg);
  aug.Read("gain_min", &a->gain_min);
  aug.Read("gain_max", &a->gain_max);
  aug.Read("noise_rect_probability", &a->noise_rect_probability);
  aug.Read("noise_rect_max_side", &a->noise_rect_max_side);
  aug.RejectUnknownKeys();
}

// train.*: optimisation, checkpoints, validation and the run folder.
void ReadTrain(Section train, const std::string& path, PoemTrainerOptions* t) {
  t->steps = 20000;
  train.Read("steps", &t->steps);
  train.Read("batch_size", &t->batch_size);
  train.Read("learning_rate", &t->learning_rate);
  train.Read("warmup_steps", &t->warmup_steps);
  train.Read("decay_at", &t->decay_at);
  train.Read("decay_factor", &t->decay_factor);
  train.Read("grad_clip_norm", &t->grad_clip_norm);
  train.Read("checkpoint_every", &t->checkpoint_every);
  train.Read("keep_checkpoints", &t->keep_checkpoints);
  train.Read("keep_every", &t->keep_every);
  train.Read("log_every", &t->log_every);
  train.Read("validate_every", &t->validate_every);
  train.Read("validation_samples", &t->validation_samples);
  train.Read("validate_at_start", &t->validate_at_start);
  train.Read("seed", &t->seed);
  train.Read("threads", &t->threads);
  train.Read("prefetch_batches", &t->prefetch_batches);
  train.Read("out_dir", &t->out_dir);
  std::string trainable = "all";
  train.Read("trainable", &trainable);
  if (trainable != "all" && trainable != "mask_head") {
    throw InputError(path, "train.trainable", "all or mask_head", trainable);
  }
  t->mask_head_only = trainable == "mask_head";
  train.RejectUnknownKeys();
}

// loss.*: the weights of the loss terms.
void ReadLoss(Section loss, PoemTrainerOptions* t) {
  loss.Read("heatmap_weight", &t->heatmap_weight);
  loss.Read("triangulation_weight", &t->triangulation_weight);
  loss.Read("joints_weight", &t->joints_weight);
  loss.Read("vertices_weight", &t->vertices_weight);
  loss.Read("joints_2d_weight", &t->joints_2d_weight);
  loss.Read("mask_weight", &t->mask_weight);
  loss.RejectUnknownKeys();
}

}  // namespace

TrainConfigFields ReadTrainConfigYaml(const std::string& path) {
  const YAML::Node root = ReadYamlFile(path);
  TrainConfigFields out;
  TrainConfig& c = out.config;
  c.source_file = path;
  Section top(root, path, "");
  top.Read("network", &c.network_name);
  top.Read("hand_model", &c.hand_model);
  ReadData(top.Child("data"), &c);
  ReadAugment(top.Child("augment"), &c.samples.augment);
  ReadTrain(top.Child("train"), path, &c.trainer);
  ReadLoss(top.Child("loss"), &c.trainer);
  const YAML::Node overrides = top.Raw("network_overrides");
  top.RejectUnknownKeys();
  if (overrides && !overrides.IsNull()) {
    if (!overrides.IsMap()) throw InputError(path, "network_overrides", "a mapping");
    try {
      out.network_overrides_json = ToJson(overrides).dump();
    } catch (const YAML::Exception& e) {  // a key that is a list or a mapping
      throw InputError(path, "network_overrides", "a mapping of plain keys", e.what());
    } catch (const nlohmann::json::exception& e) {  // text that is not UTF-8
      throw InputError(path, "network_overrides", "UTF-8 text", e.what());
    }
  }
  return out;
}

}  // namespace handlabel
