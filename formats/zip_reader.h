#pragma once
// Reads zip archives: numpy .npz (np.savez / np.savez_compressed), torch.save
// checkpoints and our own model files. Supports stored and deflate entries and zip64
// (sizes, offsets and entry counts beyond 32 bits). Every size and offset read from
// the file is checked against the file before it is used, entry sizes are capped
// (ZipLimits), CRC-32 is verified, and encrypted or multi-disk archives are rejected.
// Spec: PKWARE APPNOTE.TXT 6.3.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "formats/npy.h"

namespace handlabel {

struct ZipEntry {
  std::string name;
  uint16_t method = 0;  // 0 stored, 8 deflate
  uint16_t flags = 0;
  uint32_t crc32 = 0;
  uint64_t compressed_size = 0;
  uint64_t uncompressed_size = 0;
  uint64_t local_header_offset = 0;
};

struct ZipLimits {
  int64_t max_entry_bytes = kDefaultMaxArrayBytes;  // largest entry we inflate
  int64_t max_entries = int64_t{1} << 20;           // central directory entries
};

class ZipReader {
 public:
  // Reads the central directory; entries are read on demand with pread (file) or from
  // memory. Reading entries is thread-safe.
  static ZipReader OpenFile(const std::string& path, const ZipLimits& limits = {});
  static ZipReader FromBytes(std::string bytes, const std::string& source,
                             const ZipLimits& limits = {});

  const std::string& source() const;
  const std::vector<ZipEntry>& entries() const;
  const ZipEntry* Find(const std::string& name) const;  // nullptr if absent
  // The entry's uncompressed bytes; throws InputError "<source>: entry '<name>' ..."
  std::string Read(const std::string& name) const;
  std::string Read(const ZipEntry& entry) const;

  class ByteSource;

 private:
  ZipReader() = default;
  void ParseCentralDirectory();

  std::shared_ptr<ByteSource> bytes_;
  std::string source_;
  ZipLimits limits_;
  std::vector<ZipEntry> entries_;
};

// True if `bytes` starts like a zip archive (local file header signature).
bool LooksLikeZip(const std::string& first_bytes);

}  // namespace handlabel
