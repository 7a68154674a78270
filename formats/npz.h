#pragma once
// numpy .npz archives: a zip of .npy files (np.savez stores, np.savez_compressed
// deflates). Object arrays inside are not decoded here (see hand_model_io.cc).

#include <string>
#include <utility>
#include <vector>

#include "formats/nd_array.h"
#include "formats/zip_writer.h"

namespace handlabel {

using NamedArrays = std::vector<std::pair<std::string, NdArray>>;

// Writes the arrays in the given order; names get the ".npy" suffix numpy expects.
// Atomic: a temporary in the same folder is renamed over `path` when complete and
// removed when a write fails (InputError naming the file); creates missing folders.
void WriteNpzFile(const std::string& path, const NamedArrays& arrays,
                  ZipMethod method = ZipMethod::kStored);
// Reads every array of an .npz (names without ".npy"), in archive order.
NamedArrays ReadNpzFile(const std::string& path);

}  // namespace handlabel
