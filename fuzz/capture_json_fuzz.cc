// libFuzzer target for the native capture's JSON files (capture/capture_format.h): the
// first byte picks the reader (manifest, keypoints / detections, ground truth), the
// rest is the file. Decoded or InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <string>

#include "capture/capture_format.h"
#include "core/errors.h"
#include "core/json_util.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  const std::string bytes(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const nlohmann::json j = handlabel::ParseJsonStrict(bytes, "fuzz.json");
    switch (data[0] % 3) {
      case 0:
        handlabel::ManifestFromJson(j, "capture.json");
        break;
      case 1:
        handlabel::ViewKeypointsFromJson(j, "keypoints.json");
        break;
      default:
        handlabel::GroundTruthFromJson(j, "ground_truth.json");
        break;
    }
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
