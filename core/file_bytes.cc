#include "core/file_bytes.h"

#include <fstream>

#include "core/errors.h"

namespace handlabel {

std::string ReadFileBytes(const std::string& path, const std::string& what) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  if (!in) throw InputError(path, "file", "an existing readable " + what, "cannot open");
  const std::streamoff size = in.tellg();
  if (size < 0)
    throw InputError(path, "file", "a readable " + what, "not a regular file");
  std::string bytes(static_cast<size_t>(size), '\0');
  in.seekg(0);
  in.read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!in) throw InputError(path, "file", "a readable " + what, "read error");
  return bytes;
}

}  // namespace handlabel
