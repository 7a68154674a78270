#pragma once
// The YAML layer of training configs (pipeline/train_config.h): every field of the file
// read into a TrainConfig, unknown, repeated and mistyped keys refused by name. The
// checks that need the rig presets, the generator or the network follow in
// LoadTrainConfig; apart so that the parser can be fuzzed alone
// (fuzz/train_config_fuzz.cc).

#include <string>

#include "pipeline/train_config.h"

namespace handlabel {

struct TrainConfigFields {
  TrainConfig config;  // the file's fields over the defaults; network not yet resolved
  // network_overrides as a JSON object ("" when absent), for PoemConfig::FromJson.
  std::string network_overrides_json;
};

// Throws InputError naming the file and field.
TrainConfigFields ReadTrainConfigYaml(const std::string& path);

}  // namespace handlabel
