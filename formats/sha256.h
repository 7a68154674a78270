#pragma once
// SHA-256 (FIPS 180-4), for provenance: the hash of the network weights a label came
// from and of the job that produced it. Small and dependency-free on purpose.

#include <cstdint>
#include <string>

namespace handlabel {

class Sha256 {
 public:
  Sha256();
  void Update(const void* data, size_t size);
  void Update(const std::string& text) { Update(text.data(), text.size()); }
  // Lower-case hex digest (64 characters). The object must not be updated afterwards.
  std::string HexDigest();

 private:
  void Compress(const uint8_t* block);
  uint32_t state_[8];
  uint8_t buffer_[64];
  size_t buffered_ = 0;
  uint64_t total_bytes_ = 0;
};

std::string Sha256Hex(const std::string& data);
// Hash of a file's bytes, streamed. Throws InputError naming the file if unreadable.
std::string Sha256OfFile(const std::string& path);

}  // namespace handlabel
