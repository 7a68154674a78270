#pragma once
// A whole file as bytes, read with one sized read (a character-by-character stream
// read was 4 % of a labeling job's time: images are read for every view of every frame).

#include <string>

namespace handlabel {

// Throws InputError naming `path` ("an existing readable <what>") when the file is
// missing or cannot be read.
std::string ReadFileBytes(const std::string& path, const std::string& what);

}  // namespace handlabel
