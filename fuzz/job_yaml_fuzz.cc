// libFuzzer target for labeling job files (pipeline/job_config.h): YAML through
// yaml-cpp and the Section reader (pipeline/yaml_section.h, shared with the training
// config): duplicate and unknown keys, types, ranges. Loaded or InputError.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "fuzz/fuzz_files.h"
#include "pipeline/job_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = handlabel::fuzz::WriteScratchFile(
      "job.yaml", std::string(reinterpret_cast<const char*>(data), size));
  try {
    handlabel::LoadJobConfig(path);
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
