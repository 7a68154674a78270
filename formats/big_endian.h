#pragma once
// Big-endian (network order) integers in byte streams: PNG chunks, SHA-256 words.

#include <cstdint>

namespace handlabel {

inline uint32_t ReadBigEndian32(const unsigned char* p) {
  return (uint32_t(p[0]) << 24) | (uint32_t(p[1]) << 16) | (uint32_t(p[2]) << 8) |
         uint32_t(p[3]);
}

}  // namespace handlabel
