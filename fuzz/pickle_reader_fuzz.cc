// libFuzzer target for the restricted pickle reader (formats/pickle_reader.h): any input
// must either decode or throw InputError; anything else (a crash, a sanitizer report,
// another exception type, a timeout or an out-of-memory) is a finding.
// Build and run: docs/fuzzing.md.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/errors.h"
#include "formats/pickle_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  handlabel::PickleLimits limits;
  limits.max_values = 1 << 16;  // keep each run fast and small
  limits.max_total_bytes = 64 << 20;
  try {
    const handlabel::PickleValue v = handlabel::ReadPickle(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz", limits);
    (void)v.Describe();
  } catch (const handlabel::InputError&) {
  }
  return 0;
}
