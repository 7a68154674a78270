// libFuzzer target for torch.save archives read without LibTorch
// (formats/torch_archive.h): the zip, data.pkl through the pickle reader and every
// tensor's storage checked against its shape and strides. Decoded or InputError.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "formats/torch_archive.h"
#include "fuzz/fuzz_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = handlabel::fuzz::WriteScratchFile(
      "fuzz.pt", std::string(reinterpret_cast<const char*>(data), size));
  try {
    handlabel::TorchArchive(path).Tensors();
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
