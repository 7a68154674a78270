#include "formats/npz.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "core/errors.h"

#include "formats/npy.h"
#include "formats/zip_reader.h"

namespace handlabel {

void WriteNpzFile(const std::string& path, const NamedArrays& arrays, ZipMethod method) {
  // A temporary in the target's folder, renamed over it when complete; removed when a
  // write fails (a full disk left "<file>.tmp" behind before).
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) std::filesystem::create_directories(parent);
  const std::string temporary = path + ".tmp." + std::to_string(::getpid());
  try {
    ZipWriter zip(temporary);
    for (const auto& [name, array] : arrays)
      zip.Add(name + ".npy", SerializeNpy(array), method);
    zip.Close();
    if (std::rename(temporary.c_str(), path.c_str()) != 0) {
      throw InputError(path, "", "a writable location", std::strerror(errno));
    }
  } catch (const InputError& e) {  // ZipWriter names the temporary: name the file meant
    std::remove(temporary.c_str());
    throw InputError(path, e.field(), e.expected(), e.got());
  } catch (...) {
    std::remove(temporary.c_str());
    throw;
  }
}

NamedArrays ReadNpzFile(const std::string& path) {
  const ZipReader zip = ZipReader::OpenFile(path);
  NamedArrays arrays;
  for (const ZipEntry& e : zip.entries()) {
    std::string name = e.name;
    if (name.size() > 4 && name.compare(name.size() - 4, 4, ".npy") == 0) {
      name.resize(name.size() - 4);
    }
    arrays.emplace_back(name, ParseNpy(zip.Read(e), path + ":" + e.name));
  }
  return arrays;
}

}  // namespace handlabel
