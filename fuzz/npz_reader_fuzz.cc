// libFuzzer target for the zip and .npy readers (formats/zip_reader.h, formats/npy.h) as
// LoadHandModel uses them on .npz files: every entry is read (inflate, CRC) and parsed
// as .npy, object arrays through the pickle reader. Inputs that do not start like a
// zip are parsed as one .npy file. Anything but success or InputError is a finding.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "formats/npy.h"
#include "formats/pickle_reader.h"
#include "formats/zip_reader.h"

namespace {

void ParseEntry(const std::string& bytes) {
  const handlabel::NpyHeader header = handlabel::ParseNpyHeader(bytes, "fuzz.npy");
  if (header.is_object) {
    handlabel::PickleLimits limits;
    limits.max_values = 1 << 16;
    limits.max_total_bytes = 64 << 20;
    handlabel::ReadPickle(bytes.substr(header.data_offset), "fuzz.npy", limits);
  } else {
    handlabel::ParseNpy(bytes, "fuzz.npy", 64 << 20);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  try {
    if (handlabel::LooksLikeZip(bytes)) {
      handlabel::ZipLimits limits;
      limits.max_entry_bytes = 64 << 20;
      limits.max_entries = 1 << 12;
      const handlabel::ZipReader zip =
          handlabel::ZipReader::FromBytes(bytes, "fuzz.npz", limits);
      for (const handlabel::ZipEntry& e : zip.entries()) {
        try {
          ParseEntry(zip.Read(e));
        } catch (const handlabel::InputError&) {
        }
      }
    } else {
      ParseEntry(bytes);
    }
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
