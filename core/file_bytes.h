#pragma once
// A whole file as bytes, read with one sized read: the one file reader of images, JSON,
// .npy, pickle, zip-based models, COLMAP binaries and .tflite files (a
// character-by-character stream read was 4 % of a labeling job's time).

#include <string>

namespace handlabel {

// Throws InputError naming `path` ("an existing readable <what>") when the file is
// missing or cannot be read.
std::string ReadFileBytes(const std::string& path, const std::string& what);

}  // namespace handlabel
