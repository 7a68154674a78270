// libFuzzer target for the COLMAP model readers (cameras/colmap_model.h) and the rig
// built from a model (cameras/colmap_rig.h). The first byte picks text or binary; the
// rest is cut at "@@@@" into cameras, images and points3D, written as files.
// Decoded or InputError, nothing else.

#include <cstddef>
#include <cstdint>
#include <string>

#include "cameras/colmap_model.h"
#include "cameras/colmap_rig.h"
#include "core/errors.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size < 1) return 0;
  using handlabel::fuzz::WriteScratchFile;
  const bool text = data[0] % 2 == 0;
  const auto parts = handlabel::fuzz::SplitInput(
      std::string(reinterpret_cast<const char*>(data) + 1, size - 1), "@@@@", 3);
  const std::string ext = text ? ".txt" : ".bin";
  WriteScratchFile("cameras" + ext, parts[0]);
  WriteScratchFile("images" + ext, parts[1]);
  WriteScratchFile("points3D" + ext, parts[2]);
  const std::string dir = handlabel::fuzz::ScratchFolder();
  try {
    const handlabel::ColmapModel model =
        text ? handlabel::ReadColmapText(dir) : handlabel::ReadColmapBinary(dir);
    handlabel::RigFromColmap(model, dir);
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
