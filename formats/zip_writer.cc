#include "formats/zip_writer.h"

#include <zlib.h>

#include <algorithm>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

constexpr uint64_t k32Max = 0xFFFFFFFF;
constexpr uint16_t kDosDate1980 = (0 << 9) | (1 << 5) | 1;  // 1980-01-01
constexpr uint16_t kPaddingExtraId = 0x6c68;                // private: alignment padding

void PutLE(uint64_t v, int bytes, std::string* out) {
  for (int k = 0; k < bytes; ++k)
    out->push_back(static_cast<char>((v >> (8 * k)) & 0xFF));
}

std::string Deflate(const std::string& data, int level, const std::string& path) {
  z_stream z{};
  if (deflateInit2(&z, level, Z_DEFLATED, -MAX_WBITS, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw Error("zlib deflateInit2 failed");
  }
  std::string out;
  size_t in_pos = 0;
  char buffer[1 << 16];
  int status = Z_OK;
  while (status != Z_STREAM_END) {
    const size_t in_chunk = std::min<size_t>(data.size() - in_pos, 1u << 30);
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()) + in_pos);
    z.avail_in = static_cast<uInt>(in_chunk);
    const bool last = in_pos + in_chunk == data.size();
    do {
      z.next_out = reinterpret_cast<Bytef*>(buffer);
      z.avail_out = sizeof(buffer);
      status = deflate(&z, last ? Z_FINISH : Z_NO_FLUSH);
      if (status == Z_STREAM_ERROR) {
        deflateEnd(&z);
        throw InputError(path, "", "deflate to succeed", "zlib stream error");
      }
      out.append(buffer, sizeof(buffer) - z.avail_out);
    } while (z.avail_out == 0 || (last && status != Z_STREAM_END));
    in_pos += in_chunk - z.avail_in;
  }
  deflateEnd(&z);
  return out;
}

uint32_t Crc32(const std::string& data) {
  uLong crc = crc32(0L, Z_NULL, 0);
  for (size_t p = 0; p < data.size(); p += 1u << 30) {
    const size_t n = std::min<size_t>(data.size() - p, 1u << 30);
    crc =
        crc32(crc, reinterpret_cast<const Bytef*>(data.data() + p), static_cast<uInt>(n));
  }
  return static_cast<uint32_t>(crc);
}

}  // namespace

void ZipWriterOptions::Check(const std::string& source) const {
  // The field names the struct: `source` is the archive, which has no such field.
  RequireInRange(source, "ZipWriterOptions.deflate_level", deflate_level, 1, 9);
}

ZipWriter::ZipWriter(const std::string& path, const ZipWriterOptions& options)
    : path_(path), options_(options) {
  options_.Check(path);
  out_.open(path, std::ios::binary | std::ios::trunc);
  if (!out_) throw InputError(path, "", "a writable file", "cannot create");
}

ZipWriter::~ZipWriter() {
  if (!closed_) {
    try {
      Close();
    } catch (...) {
    }
  }
}

void ZipWriter::Write(const std::string& bytes) {
  out_.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out_) throw InputError(path_, "", "a writable file", "write failed");
  offset_ += bytes.size();
}

void ZipWriter::Add(const std::string& name, const std::string& data, ZipMethod method,
                    uint32_t alignment) {
  HL_CHECK(!closed_, "ZipWriter::Add after Close");
  if (name.empty() || name.size() > 0xFFFF) {
    throw InputError(path_, "entry name", "1 to 65535 bytes",
                     std::to_string(name.size()));
  }
  ZipEntry e;
  e.name = name;
  e.method = method == ZipMethod::kDeflate ? 8 : 0;
  e.flags = std::any_of(name.begin(), name.end(), [](char c) { return c & 0x80; })
                ? 0x0800  // UTF-8 name
                : 0;
  e.crc32 = Crc32(data);
  e.uncompressed_size = data.size();
  e.local_header_offset = offset_;
  const std::string packed =
      method == ZipMethod::kDeflate ? Deflate(data, options_.deflate_level, path_) : "";
  const std::string& payload = method == ZipMethod::kDeflate ? packed : data;
  e.compressed_size = payload.size();
  const bool zip64 = options_.force_zip64 || e.uncompressed_size >= k32Max ||
                     e.compressed_size >= k32Max;

  std::string extra;
  if (zip64) {
    PutLE(0x0001, 2, &extra);
    PutLE(16, 2, &extra);
    PutLE(e.uncompressed_size, 8, &extra);
    PutLE(e.compressed_size, 8, &extra);
  }
  if (alignment > 1) {
    const uint64_t data_start = offset_ + 30 + name.size() + extra.size();
    uint64_t pad = (alignment - data_start % alignment) % alignment;
    if (pad > 0 && pad < 4) pad += alignment;  // an extra block needs 4 header bytes
    if (pad > 0) {
      PutLE(kPaddingExtraId, 2, &extra);
      PutLE(pad - 4, 2, &extra);
      extra.append(pad - 4, '\0');
    }
  }
  std::string header;
  PutLE(0x04034b50, 4, &header);
  PutLE(zip64 ? 45 : 20, 2, &header);
  PutLE(e.flags, 2, &header);
  PutLE(e.method, 2, &header);
  PutLE(0, 2, &header);  // time
  PutLE(kDosDate1980, 2, &header);
  PutLE(e.crc32, 4, &header);
  PutLE(zip64 ? k32Max : e.compressed_size, 4, &header);
  PutLE(zip64 ? k32Max : e.uncompressed_size, 4, &header);
  PutLE(name.size(), 2, &header);
  PutLE(extra.size(), 2, &header);
  header += name;
  header += extra;
  Write(header);
  Write(payload);
  entries_.push_back(std::move(e));
}

void ZipWriter::Close() {
  if (closed_) return;
  closed_ = true;
  const uint64_t cd_offset = offset_;
  std::string cd;
  for (const ZipEntry& e : entries_) {
    const bool zip64 = options_.force_zip64 || e.uncompressed_size >= k32Max ||
                       e.compressed_size >= k32Max || e.local_header_offset >= k32Max;
    std::string extra;
    if (zip64) {
      PutLE(0x0001, 2, &extra);
      PutLE(24, 2, &extra);
      PutLE(e.uncompressed_size, 8, &extra);
      PutLE(e.compressed_size, 8, &extra);
      PutLE(e.local_header_offset, 8, &extra);
    }
    PutLE(0x02014b50, 4, &cd);
    PutLE(zip64 ? 45 : 20, 2, &cd);  // made by (MS-DOS attributes)
    PutLE(zip64 ? 45 : 20, 2, &cd);  // needed
    PutLE(e.flags, 2, &cd);
    PutLE(e.method, 2, &cd);
    PutLE(0, 2, &cd);
    PutLE(kDosDate1980, 2, &cd);
    PutLE(e.crc32, 4, &cd);
    PutLE(zip64 ? k32Max : e.compressed_size, 4, &cd);
    PutLE(zip64 ? k32Max : e.uncompressed_size, 4, &cd);
    PutLE(e.name.size(), 2, &cd);
    PutLE(extra.size(), 2, &cd);
    PutLE(0, 2, &cd);  // comment
    PutLE(0, 2, &cd);  // disk
    PutLE(0, 2, &cd);  // internal attributes
    PutLE(0, 4, &cd);  // external attributes
    PutLE(zip64 ? k32Max : e.local_header_offset, 4, &cd);
    cd += e.name;
    cd += extra;
  }
  Write(cd);
  const uint64_t cd_size = cd.size();
  const uint64_t count = entries_.size();
  const bool zip64_end =
      options_.force_zip64 || count >= 0xFFFF || cd_offset >= k32Max || cd_size >= k32Max;
  std::string end;
  if (zip64_end) {
    const uint64_t z64_offset = offset_;
    PutLE(0x06064b50, 4, &end);
    PutLE(44, 8, &end);  // size of the rest of this record
    PutLE(45, 2, &end);
    PutLE(45, 2, &end);
    PutLE(0, 4, &end);
    PutLE(0, 4, &end);
    PutLE(count, 8, &end);
    PutLE(count, 8, &end);
    PutLE(cd_size, 8, &end);
    PutLE(cd_offset, 8, &end);
    PutLE(0x07064b50, 4, &end);  // locator
    PutLE(0, 4, &end);
    PutLE(z64_offset, 8, &end);
    PutLE(1, 4, &end);
  }
  PutLE(0x06054b50, 4, &end);
  PutLE(0, 2, &end);
  PutLE(0, 2, &end);
  PutLE(zip64_end ? 0xFFFF : count, 2, &end);
  PutLE(zip64_end ? 0xFFFF : count, 2, &end);
  PutLE(zip64_end ? k32Max : cd_size, 4, &end);
  PutLE(zip64_end ? k32Max : cd_offset, 4, &end);
  PutLE(0, 2, &end);
  Write(end);
  out_.close();
  if (!out_) throw InputError(path_, "", "a writable file", "close failed");
}

}  // namespace handlabel
