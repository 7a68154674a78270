#include "formats/zip_reader.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>

#include <algorithm>
#include <cstring>

#include "core/errors.h"

namespace handlabel {

// Random access to the archive's bytes.
class ZipReader::ByteSource {
 public:
  virtual ~ByteSource() = default;
  virtual uint64_t size() const = 0;
  // Reads exactly n bytes at offset (caller has checked the range).
  virtual void ReadAt(uint64_t offset, size_t n, char* out) const = 0;
};

namespace {

constexpr uint32_t kLocalHeaderSig = 0x04034b50;
constexpr uint32_t kCentralHeaderSig = 0x02014b50;
constexpr uint32_t kEndSig = 0x06054b50;
constexpr uint32_t kZip64EndSig = 0x06064b50;
constexpr uint32_t kZip64LocatorSig = 0x07064b50;
constexpr size_t kEndSize = 22;
constexpr size_t kCentralHeaderSize = 46;
constexpr size_t kLocalHeaderSize = 30;
// Deflate's largest expansion: a 258-byte match coded in 2 bits, 1032 bytes out per byte
// in. A larger declared size is impossible, and refused before we allocate for it.
constexpr uint64_t kMaxDeflateRatio = 1032;

class MemorySource : public ZipReader::ByteSource {
 public:
  explicit MemorySource(std::string bytes) : bytes_(std::move(bytes)) {}
  uint64_t size() const override { return bytes_.size(); }
  void ReadAt(uint64_t offset, size_t n, char* out) const override {
    std::memcpy(out, bytes_.data() + offset, n);
  }

 private:
  std::string bytes_;
};

class FileSource : public ZipReader::ByteSource {
 public:
  explicit FileSource(const std::string& path) : path_(path) {
    fd_ = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd_ < 0) throw InputError(path, "", "a readable file", std::strerror(errno));
    struct stat st;
    if (::fstat(fd_, &st) != 0 || !S_ISREG(st.st_mode)) {
      ::close(fd_);
      throw InputError(path, "", "a regular file");
    }
    size_ = static_cast<uint64_t>(st.st_size);
  }
  ~FileSource() override { ::close(fd_); }
  uint64_t size() const override { return size_; }
  void ReadAt(uint64_t offset, size_t n, char* out) const override {
    while (n > 0) {
      const ssize_t got = ::pread(fd_, out, n, static_cast<off_t>(offset));
      if (got <= 0) throw InputError(path_, "", "readable bytes", "read error");
      out += got;
      n -= static_cast<size_t>(got);
      offset += static_cast<uint64_t>(got);
    }
  }

 private:
  std::string path_;
  int fd_ = -1;
  uint64_t size_ = 0;
};

uint64_t LoadLE(const char* p, int bytes) {
  uint64_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) v = (v << 8) | static_cast<uint8_t>(p[k]);
  return v;
}

// A bounds-checked little-endian cursor over a block of bytes.
class Cursor {
 public:
  Cursor(const std::string& block, const std::string& source, const char* what)
      : block_(block), source_(source), what_(what) {}
  uint64_t Get(int bytes) {
    Need(bytes);
    const uint64_t v = LoadLE(block_.data() + pos_, bytes);
    pos_ += bytes;
    return v;
  }
  std::string Take(size_t n) {
    Need(n);
    std::string s = block_.substr(pos_, n);
    pos_ += n;
    return s;
  }
  void Skip(size_t n) {
    Need(n);
    pos_ += n;
  }
  size_t pos() const { return pos_; }
  size_t remaining() const { return block_.size() - pos_; }

 private:
  void Need(size_t n) const {
    if (n > block_.size() - pos_) {
      throw InputError(source_, what_, "a complete record", "truncated archive");
    }
  }
  const std::string& block_;
  const std::string& source_;
  const char* what_;
  size_t pos_ = 0;
};

}  // namespace

bool LooksLikeZip(const std::string& first_bytes) {
  return first_bytes.size() >= 4 && LoadLE(first_bytes.data(), 4) == kLocalHeaderSig;
}

ZipReader ZipReader::OpenFile(const std::string& path, const ZipLimits& limits) {
  ZipReader r;
  r.bytes_ = std::make_shared<FileSource>(path);
  r.source_ = path;
  r.limits_ = limits;
  r.ParseCentralDirectory();
  return r;
}

ZipReader ZipReader::FromBytes(std::string bytes, const std::string& source,
                               const ZipLimits& limits) {
  ZipReader r;
  r.bytes_ = std::make_shared<MemorySource>(std::move(bytes));
  r.source_ = source;
  r.limits_ = limits;
  r.ParseCentralDirectory();
  return r;
}

const std::string& ZipReader::source() const { return source_; }
const std::vector<ZipEntry>& ZipReader::entries() const { return entries_; }

const ZipEntry* ZipReader::Find(const std::string& name) const {
  for (const ZipEntry& e : entries_) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

namespace {

// n bytes at `offset`, refusing ranges beyond the end of the file.
std::string ReadBlock(const ZipReader::ByteSource& bytes, const std::string& source,
                      uint64_t offset, uint64_t n, const char* what) {
  const uint64_t file_size = bytes.size();
  if (offset > file_size || n > file_size - offset) {
    throw InputError(source, what, "a record inside the file", "offset out of range");
  }
  std::string block(static_cast<size_t>(n), '\0');
  bytes.ReadAt(offset, static_cast<size_t>(n), block.data());
  return block;
}

// Where the central directory lies and how many entries it holds.
struct CentralDirectoryPlace {
  uint64_t disk = 0, cd_disk = 0;  // both 0 for a single-disk archive
  uint64_t count = 0, size = 0, offset = 0;
};

// Reads the end of central directory record (searched backwards over the comment) and,
// when a zip64 locator sits directly before it, the zip64 end record.
CentralDirectoryPlace FindCentralDirectory(const ZipReader::ByteSource& bytes,
                                           const std::string& source) {
  const uint64_t file_size = bytes.size();
  if (file_size < kEndSize) {
    throw InputError(source, "", "a zip archive",
                     "a file of " + std::to_string(file_size) + " bytes");
  }
  // The end record sits in the last 22 + (up to 65535 comment) bytes.
  const uint64_t tail_size = std::min<uint64_t>(file_size, kEndSize + 0xFFFF);
  const std::string tail =
      ReadBlock(bytes, source, file_size - tail_size, tail_size, "end record");
  size_t end_pos = std::string::npos;
  for (size_t p = tail.size() - kEndSize + 1; p-- > 0;) {
    if (LoadLE(tail.data() + p, 4) == kEndSig) {
      end_pos = p;
      break;
    }
  }
  if (end_pos == std::string::npos) {
    throw InputError(source, "", "a zip archive (end of central directory record)",
                     "none found: not a zip file or truncated");
  }
  const uint64_t end_offset = file_size - tail_size + end_pos;
  Cursor end(tail, source, "end record");
  end.Skip(end_pos + 4);
  CentralDirectoryPlace place;
  place.disk = end.Get(2);
  place.cd_disk = end.Get(2);
  end.Get(2);
  place.count = end.Get(2);
  place.size = end.Get(4);
  place.offset = end.Get(4);
  // A zip64 locator directly before the end record points at the zip64 end record.
  if (end_offset >= 20) {
    const std::string loc =
        ReadBlock(bytes, source, end_offset - 20, 20, "zip64 locator");
    if (LoadLE(loc.data(), 4) == kZip64LocatorSig) {
      const uint64_t z64_offset = LoadLE(loc.data() + 8, 8);
      const std::string z64 =
          ReadBlock(bytes, source, z64_offset, 56, "zip64 end record");
      if (LoadLE(z64.data(), 4) != kZip64EndSig) {
        throw InputError(source, "zip64 end record", "signature PK\\6\\6");
      }
      place.count = LoadLE(z64.data() + 32, 8);
      place.size = LoadLE(z64.data() + 40, 8);
      place.offset = LoadLE(z64.data() + 48, 8);
    }
  }
  return place;
}

// One central directory header (entry number i) at the cursor.
ZipEntry ParseCentralEntry(Cursor* c, const std::string& source, uint64_t i) {
  if (c->Get(4) != kCentralHeaderSig) {
    throw InputError(source, "central directory",
                     "entry signature PK\\1\\2 at entry " + std::to_string(i));
  }
  ZipEntry e;
  c->Skip(4);  // versions
  e.flags = static_cast<uint16_t>(c->Get(2));
  e.method = static_cast<uint16_t>(c->Get(2));
  c->Skip(4);  // time, date
  e.crc32 = static_cast<uint32_t>(c->Get(4));
  e.compressed_size = c->Get(4);
  e.uncompressed_size = c->Get(4);
  const size_t name_len = c->Get(2), extra_len = c->Get(2), comment_len = c->Get(2);
  c->Skip(8);  // disk, internal and external attributes
  e.local_header_offset = c->Get(4);
  e.name = c->Take(name_len);
  const std::string extra = c->Take(extra_len);
  c->Skip(comment_len);
  // Zip64 extra field: 64-bit values for the fields that hold 0xFFFFFFFF, in order.
  Cursor x(extra, source, "zip64 extra field");
  while (x.remaining() >= 4) {
    const uint64_t id = x.Get(2), size = x.Get(2);
    const std::string body = x.Take(size);
    if (id != 0x0001) continue;
    Cursor z(body, source, "zip64 extra field");
    if (e.uncompressed_size == 0xFFFFFFFF) e.uncompressed_size = z.Get(8);
    if (e.compressed_size == 0xFFFFFFFF) e.compressed_size = z.Get(8);
    if (e.local_header_offset == 0xFFFFFFFF) e.local_header_offset = z.Get(8);
  }
  return e;
}

}  // namespace

void ZipReader::ParseCentralDirectory() {
  const CentralDirectoryPlace place = FindCentralDirectory(*bytes_, source_);
  if (place.disk != 0 || place.cd_disk != 0) {
    throw InputError(source_, "", "a single-disk archive", "a multi-disk archive");
  }
  if (place.count > static_cast<uint64_t>(limits_.max_entries)) {
    throw InputError(source_, "entries",
                     "at most " + std::to_string(limits_.max_entries) + " entries",
                     std::to_string(place.count));
  }
  if (place.count * kCentralHeaderSize > place.size) {
    throw InputError(source_, "central directory",
                     std::to_string(place.count) + " entries in " +
                         std::to_string(place.size) + " bytes",
                     "inconsistent sizes");
  }
  const std::string cd =
      ReadBlock(*bytes_, source_, place.offset, place.size, "central directory");
  Cursor c(cd, source_, "central directory");
  entries_.reserve(static_cast<size_t>(place.count));
  for (uint64_t i = 0; i < place.count; ++i) {
    entries_.push_back(ParseCentralEntry(&c, source_, i));
  }
}

std::string ZipReader::Read(const std::string& name) const {
  const ZipEntry* e = Find(name);
  if (!e) throw InputError(source_, name, "an entry named '" + name + "'", "none");
  return Read(*e);
}

std::string ZipReader::Read(const ZipEntry& e) const {
  const std::string field = "entry '" + e.name + "'";
  if (e.flags & 0x1) throw InputError(source_, field, "an unencrypted entry");
  if (e.method != 0 && e.method != 8) {
    throw InputError(source_, field, "stored (0) or deflate (8) compression",
                     "method " + std::to_string(e.method));
  }
  if (e.uncompressed_size > static_cast<uint64_t>(limits_.max_entry_bytes)) {
    throw InputError(source_, field,
                     "at most " + std::to_string(limits_.max_entry_bytes) + " bytes",
                     std::to_string(e.uncompressed_size) + " bytes declared");
  }
  const uint64_t file_size = bytes_->size();
  if (e.local_header_offset > file_size ||
      file_size - e.local_header_offset < kLocalHeaderSize) {
    throw InputError(source_, field, "a local header inside the file", "out of range");
  }
  char header[kLocalHeaderSize];
  bytes_->ReadAt(e.local_header_offset, kLocalHeaderSize, header);
  if (LoadLE(header, 4) != kLocalHeaderSig) {
    throw InputError(source_, field, "local header signature PK\\3\\4");
  }
  const uint64_t data_offset = e.local_header_offset + kLocalHeaderSize +
                               LoadLE(header + 26, 2) + LoadLE(header + 28, 2);
  if (data_offset > file_size || e.compressed_size > file_size - data_offset) {
    throw InputError(source_, field, std::to_string(e.compressed_size) + " bytes of data",
                     "truncated archive");
  }
  if (e.method == 8 && e.uncompressed_size / kMaxDeflateRatio > e.compressed_size) {
    throw InputError(source_, field,
                     "an uncompressed size deflate can reach from " +
                         std::to_string(e.compressed_size) + " bytes (at most " +
                         std::to_string(kMaxDeflateRatio) + " times as many)",
                     std::to_string(e.uncompressed_size) + " bytes declared");
  }
  std::string out;
  if (e.method == 0) {
    if (e.compressed_size != e.uncompressed_size) {
      throw InputError(source_, field, "equal sizes for a stored entry");
    }
    out.resize(static_cast<size_t>(e.compressed_size));
    if (!out.empty()) bytes_->ReadAt(data_offset, out.size(), out.data());
  } else {
    std::string packed(static_cast<size_t>(e.compressed_size), '\0');
    if (!packed.empty()) bytes_->ReadAt(data_offset, packed.size(), packed.data());
    out.resize(static_cast<size_t>(e.uncompressed_size));
    z_stream z{};
    if (inflateInit2(&z, -MAX_WBITS) != Z_OK) throw Error("zlib inflateInit2 failed");
    // Feed in chunks so that sizes above 4 GiB work with zlib's 32-bit counters.
    size_t in_pos = 0, out_pos = 0;
    int status = Z_OK;
    while (status == Z_OK) {
      const size_t in_chunk = std::min<size_t>(packed.size() - in_pos, 1u << 30);
      const size_t out_chunk = std::min<size_t>(out.size() - out_pos, 1u << 30);
      z.next_in = reinterpret_cast<Bytef*>(packed.data() + in_pos);
      z.avail_in = static_cast<uInt>(in_chunk);
      // One spare byte of room would let a stream longer than declared show itself.
      char spare;
      z.next_out = out_chunk ? reinterpret_cast<Bytef*>(out.data() + out_pos)
                             : reinterpret_cast<Bytef*>(&spare);
      z.avail_out = out_chunk ? static_cast<uInt>(out_chunk) : 1;
      status = inflate(&z, Z_NO_FLUSH);
      in_pos += in_chunk - z.avail_in;
      if (out_chunk) {
        out_pos += out_chunk - z.avail_out;
      } else if (z.avail_out == 0) {
        status = Z_DATA_ERROR;  // produced more than the declared size
      }
      // Z_BUF_ERROR: no progress possible with fresh buffers, i.e. truncated input.
    }
    inflateEnd(&z);
    if (status != Z_STREAM_END || out_pos != out.size()) {
      throw InputError(source_, field,
                       "a deflate stream of " + std::to_string(out.size()) + " bytes",
                       status == Z_STREAM_END ? std::to_string(out_pos) + " bytes"
                                              : "corrupt or truncated data");
    }
  }
  // CRC-32 in 1 GiB steps (zlib's length argument is 32-bit).
  uLong crc = crc32(0L, Z_NULL, 0);
  for (size_t p = 0; p < out.size(); p += 1u << 30) {
    const size_t n = std::min<size_t>(out.size() - p, 1u << 30);
    crc =
        crc32(crc, reinterpret_cast<const Bytef*>(out.data() + p), static_cast<uInt>(n));
  }
  if (crc != e.crc32) throw InputError(source_, field, "a matching CRC-32", "mismatch");
  return out;
}

}  // namespace handlabel
