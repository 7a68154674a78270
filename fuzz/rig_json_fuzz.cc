// libFuzzer target for the rig file reader (cameras/rig_json.h) behind the strict JSON
// parser (core/json_util.h): decoded or InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <string>

#include "cameras/rig_json.h"
#include "core/errors.h"
#include "core/json_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    handlabel::RigFileInfo info;
    handlabel::RigFromJson(handlabel::ParseJsonStrict(bytes, "fuzz.json"), "fuzz.json",
                           &info);
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
