// libFuzzer target for training configs' YAML layer (pipeline/train_config_yaml.h):
// yaml-cpp, the Section reader, network_overrides turned into JSON. Read or InputError.
// The checks after it (rig presets, generator and trainer options, the network) are
// replayed over this corpus in the ordinary build (TrainConfig.FuzzCorpusSmoke).

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "fuzz/fuzz_files.h"
#include "pipeline/train_config_yaml.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = handlabel::fuzz::WriteScratchFile(
      "train.yaml", std::string(reinterpret_cast<const char*>(data), size));
  try {
    handlabel::ReadTrainConfigYaml(path);
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
