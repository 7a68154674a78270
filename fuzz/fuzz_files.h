#pragma once
// For fuzz targets whose reader takes a path: the input written to files in a private
// folder (in /dev/shm when it exists, so no disk I/O per input).

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace handlabel::fuzz {

inline std::string ScratchFolder() {
  static const std::string dir = [] {
    const std::string base =
        std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    const std::string d = base + "/handlabel-fuzz-" + std::to_string(::getpid());
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

inline std::string WriteScratchFile(const std::string& name, const std::string& bytes) {
  const std::string path = ScratchFolder() + "/" + name;
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
  return path;
}

// `bytes` cut at every occurrence of `separator` into exactly `parts` pieces (the
// last takes the rest; missing pieces are empty).
inline std::vector<std::string> SplitInput(const std::string& bytes,
                                           const std::string& separator, size_t parts) {
  std::vector<std::string> out;
  size_t start = 0;
  while (out.size() + 1 < parts) {
    const size_t at = bytes.find(separator, start);
    if (at == std::string::npos) break;
    out.push_back(bytes.substr(start, at - start));
    start = at + separator.size();
  }
  out.push_back(start <= bytes.size() ? bytes.substr(start) : "");
  out.resize(parts);
  return out;
}

}  // namespace handlabel::fuzz
