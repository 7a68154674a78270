#pragma once
// Writes zip archives (stored or deflate entries, zip64 records when sizes, offsets or
// the entry count need them) such as .npz files that numpy.load reads. Timestamps are
// fixed at 1980-01-01 so the same content gives the same bytes.

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include "formats/zip_reader.h"

namespace handlabel {

enum class ZipMethod { kStored, kDeflate };

struct ZipWriterOptions {
  // Write zip64 extra fields and end records even for small archives (for tests and
  // for readers that want them); they are always written when needed.
  bool force_zip64 = false;
  int deflate_level = 6;  // zlib level 1-9 for kDeflate entries
  // Throws InputError naming `source` (the archive) and the field.
  void Check(const std::string& source) const;
};

class ZipWriter {
 public:
  // Creates (truncates) `path`; nothing is valid until Close() returns.
  explicit ZipWriter(const std::string& path, const ZipWriterOptions& options = {});
  ~ZipWriter();  // closes if Close() was not called (errors are then swallowed)
  ZipWriter(const ZipWriter&) = delete;
  ZipWriter& operator=(const ZipWriter&) = delete;

  // Adds one entry. alignment > 1 pads the local header so that the entry's data
  // starts at a multiple of it in the file (torch.save aligns tensors to 64).
  void Add(const std::string& name, const std::string& data,
           ZipMethod method = ZipMethod::kStored, uint32_t alignment = 0);
  // Writes the central directory and closes the file.
  void Close();

 private:
  void Write(const std::string& bytes);

  std::string path_;
  ZipWriterOptions options_;
  std::ofstream out_;
  uint64_t offset_ = 0;
  std::vector<ZipEntry> entries_;
  bool closed_ = false;
};

}  // namespace handlabel
