#include "formats/npz.h"

#include "formats/npy.h"
#include "formats/zip_reader.h"

namespace handlabel {

void WriteNpzFile(const std::string& path, const NamedArrays& arrays, ZipMethod method) {
  ZipWriter zip(path);
  for (const auto& [name, array] : arrays)
    zip.Add(name + ".npy", SerializeNpy(array), method);
  zip.Close();
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
