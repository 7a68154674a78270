#include "formats/npy.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include "core/errors.h"
#include "core/file_bytes.h"

namespace handlabel {
namespace {

constexpr char kMagic[] = "\x93NUMPY";
constexpr size_t kMagicSize = 6;

bool HostIsBigEndian() {
  const uint16_t one = 1;
  uint8_t first;
  std::memcpy(&first, &one, 1);
  return first == 0;
}

// The header is a Python dict literal such as
//   {'descr': '<f8', 'fortran_order': False, 'shape': (3, 4), }
// Only string, bool and int-tuple values occur for the arrays we accept.
class HeaderParser {
 public:
  HeaderParser(const std::string& text, const std::string& source)
      : text_(text), source_(source) {}

  NpyHeader Parse() {
    NpyHeader h;
    bool have_descr = false, have_order = false, have_shape = false;
    Expect('{');
    while (true) {
      SkipSpace();
      if (Peek() == '}') break;
      const std::string key = ParseString();
      Expect(':');
      SkipSpace();
      if (key == "descr") {
        if (Peek() != '\'' && Peek() != '"') {
          Fail("descr", "a plain dtype string (structured arrays are not supported)");
        }
        h.descr = ParseString();
        have_descr = true;
      } else if (key == "fortran_order") {
        h.fortran_order = ParseBool();
        have_order = true;
      } else if (key == "shape") {
        h.shape = ParseIntTuple();
        have_shape = true;
      } else {
        Fail(key, "only the keys descr, fortran_order and shape");
      }
      SkipSpace();
      if (Peek() == ',') ++pos_;
    }
    if (!have_descr || !have_order || !have_shape) {
      Fail("header", "the keys descr, fortran_order and shape");
    }
    if (h.descr == "|O" || h.descr == "O" || h.descr == "<O" || h.descr == ">O") {
      h.is_object = true;
    } else if (!ParseDTypeDescr(h.descr, &h.dtype, &h.itemsize, &h.big_endian)) {
      Fail("descr", "bool, int, uint, float16/32/64, str or bytes", h.descr);
    }
    return h;
  }

 private:
  [[noreturn]] void Fail(const std::string& field, const std::string& expected,
                         const std::string& got = "") {
    throw InputError(source_, field, expected, got.empty() ? "" : "'" + got + "'");
  }
  char Peek() const { return pos_ < text_.size() ? text_[pos_] : '\0'; }
  void SkipSpace() {
    while (pos_ < text_.size() && std::isspace(static_cast<unsigned char>(text_[pos_])))
      ++pos_;
  }
  void Expect(char c) {
    SkipSpace();
    if (Peek() != c) {
      Fail("header", std::string("'") + c + "' at offset " + std::to_string(pos_) +
                         " of the npy header");
    }
    ++pos_;
  }
  std::string ParseString() {
    SkipSpace();
    const char quote = Peek();
    if (quote != '\'' && quote != '"') Fail("header", "a quoted key");
    const size_t end = text_.find(quote, pos_ + 1);
    if (end == std::string::npos) Fail("header", "a closing quote");
    std::string s = text_.substr(pos_ + 1, end - pos_ - 1);
    pos_ = end + 1;
    return s;
  }
  bool ParseBool() {
    if (text_.compare(pos_, 4, "True") == 0) {
      pos_ += 4;
      return true;
    }
    if (text_.compare(pos_, 5, "False") == 0) {
      pos_ += 5;
      return false;
    }
    Fail("fortran_order", "True or False");
  }
  std::vector<int64_t> ParseIntTuple() {
    std::vector<int64_t> dims;
    Expect('(');
    while (true) {
      SkipSpace();
      if (Peek() == ')') {
        ++pos_;
        return dims;
      }
      if (!std::isdigit(static_cast<unsigned char>(Peek()))) {
        Fail("shape", "a tuple of non-negative integers");
      }
      int64_t v = 0;
      while (std::isdigit(static_cast<unsigned char>(Peek()))) {
        if (v > (int64_t{1} << 50)) Fail("shape", "dimensions below 2^50");
        v = v * 10 + (text_[pos_++] - '0');
      }
      if (text_.compare(pos_, 1, "L") == 0) ++pos_;  // Python 2 long suffix
      dims.push_back(v);
      if (dims.size() > 32) Fail("shape", "at most 32 dimensions");
      SkipSpace();
      if (Peek() == ',') ++pos_;
    }
  }

  const std::string& text_;
  const std::string& source_;
  size_t pos_ = 0;
};

void SwapBytes(uint8_t* p, int64_t unit, int64_t count) {
  for (int64_t i = 0; i < count; ++i, p += unit) std::reverse(p, p + unit);
}

}  // namespace

bool ParseDTypeDescr(const std::string& descr, DType* dtype, int64_t* itemsize,
                     bool* big_endian) {
  if (descr.empty()) return false;
  size_t pos = 0;
  bool big = HostIsBigEndian();
  if (descr[0] == '<' || descr[0] == '>' || descr[0] == '|' || descr[0] == '=') {
    if (descr[0] == '<') big = false;
    if (descr[0] == '>') big = true;
    pos = 1;
  }
  if (pos >= descr.size()) return false;
  const char kind = descr[pos++];
  int64_t size = 0;
  const bool sized = pos < descr.size();
  for (; pos < descr.size(); ++pos) {
    if (!std::isdigit(static_cast<unsigned char>(descr[pos])) || size > (1 << 24))
      return false;
    size = size * 10 + (descr[pos] - '0');
  }
  DType t;
  switch (kind) {
    case '?':
      if (sized && size != 1) return false;
      t = DType::kBool;
      break;
    case 'b':  // 'b1' is bool, a bare 'b' is int8 (numpy's character codes)
      if (sized && size != 1) return false;
      t = sized ? DType::kBool : DType::kInt8;
      break;
    case 'B':
      if (sized) return false;
      t = DType::kUInt8;
      break;
    case 'i':
      if (size == 1)
        t = DType::kInt8;
      else if (size == 2)
        t = DType::kInt16;
      else if (size == 4)
        t = DType::kInt32;
      else if (size == 8)
        t = DType::kInt64;
      else
        return false;
      break;
    case 'u':
      if (size == 1)
        t = DType::kUInt8;
      else if (size == 2)
        t = DType::kUInt16;
      else if (size == 4)
        t = DType::kUInt32;
      else if (size == 8)
        t = DType::kUInt64;
      else
        return false;
      break;
    case 'f':
      if (size == 2)
        t = DType::kFloat16;
      else if (size == 4)
        t = DType::kFloat32;
      else if (size == 8)
        t = DType::kFloat64;
      else
        return false;
      break;
    case 'U':
      t = DType::kUnicode;
      size *= 4;
      break;
    case 'S':
    case 'a':
      t = DType::kBytes;
      break;
    default:
      return false;
  }
  *dtype = t;
  *itemsize = IsNumeric(t) ? FixedDTypeSize(t) : size;
  *big_endian = big;
  return true;
}

std::string DTypeDescr(const NdArray& a) {
  switch (a.dtype) {
    case DType::kBool:
      return "|b1";
    case DType::kInt8:
      return "|i1";
    case DType::kUInt8:
      return "|u1";
    case DType::kInt16:
      return "<i2";
    case DType::kUInt16:
      return "<u2";
    case DType::kInt32:
      return "<i4";
    case DType::kUInt32:
      return "<u4";
    case DType::kInt64:
      return "<i8";
    case DType::kUInt64:
      return "<u8";
    case DType::kFloat16:
      return "<f2";
    case DType::kFloat32:
      return "<f4";
    case DType::kFloat64:
      return "<f8";
    case DType::kUnicode:
      return "<U" + std::to_string(a.itemsize / 4);
    case DType::kBytes:
      return "|S" + std::to_string(a.itemsize);
  }
  return "?";
}

void ToNativeCOrder(bool big_endian, bool fortran_order, NdArray* a) {
  const int64_t n = a->size();
  if (big_endian != HostIsBigEndian() && a->dtype != DType::kBytes) {
    const int64_t unit = a->dtype == DType::kUnicode ? 4 : a->itemsize;
    if (unit > 1) SwapBytes(a->data.data(), unit, n * a->itemsize / unit);
  }
  if (!fortran_order || a->ndim() < 2 || n == 0) return;
  // Element i in C order sits at Fortran offset sum_k index_k * prod_{m<k} shape_m.
  const int nd = a->ndim();
  std::vector<int64_t> f_stride(nd);
  int64_t s = 1;
  for (int k = 0; k < nd; ++k) {
    f_stride[k] = s;
    s *= a->shape[k];
  }
  std::vector<uint8_t> c_data(a->data.size());
  std::vector<int64_t> index(nd, 0);
  const int64_t item = a->itemsize;
  for (int64_t i = 0; i < n; ++i) {
    int64_t f = 0;
    for (int k = 0; k < nd; ++k) f += index[k] * f_stride[k];
    std::memcpy(c_data.data() + i * item, a->data.data() + f * item, item);
    for (int k = nd - 1; k >= 0; --k) {
      if (++index[k] < a->shape[k]) break;
      index[k] = 0;
    }
  }
  a->data.swap(c_data);
}

NpyHeader ParseNpyHeader(const std::string& bytes, const std::string& source) {
  if (bytes.size() < 10 || bytes.compare(0, kMagicSize, kMagic, kMagicSize) != 0) {
    throw InputError(source, "", "a .npy file (magic \\x93NUMPY)");
  }
  const int major = static_cast<uint8_t>(bytes[6]);
  size_t header_len, header_start;
  if (major == 1) {
    header_len = static_cast<uint8_t>(bytes[8]) | (static_cast<uint8_t>(bytes[9]) << 8);
    header_start = 10;
  } else if (major == 2 || major == 3) {
    if (bytes.size() < 12) throw InputError(source, "header", "a complete npy header");
    uint32_t len = 0;
    for (int k = 3; k >= 0; --k) len = (len << 8) | static_cast<uint8_t>(bytes[8 + k]);
    header_len = len;
    header_start = 12;
  } else {
    throw InputError(source, "version", "npy format 1.0, 2.0 or 3.0",
                     std::to_string(major));
  }
  if (header_len > bytes.size() - header_start) {
    throw InputError(source, "header", "a complete npy header", "truncated file");
  }
  const std::string text = bytes.substr(header_start, header_len);
  NpyHeader h = HeaderParser(text, source).Parse();
  h.data_offset = header_start + header_len;
  return h;
}

NdArray ParseNpy(const std::string& bytes, const std::string& source, int64_t max_bytes) {
  const NpyHeader h = ParseNpyHeader(bytes, source);
  if (h.is_object) {
    throw InputError(source, "descr", "a numeric or string array",
                     "an object array (pickled Python objects)");
  }
  NdArray a;
  a.dtype = h.dtype;
  a.itemsize = h.itemsize;
  a.shape = h.shape;
  int64_t n_bytes;
  try {
    n_bytes = CheckedByteCount(h.shape, h.itemsize, max_bytes, "array");
  } catch (const Error& e) {
    throw InputError(source, "shape", "a size within limits", e.what());
  }
  const size_t available = bytes.size() - h.data_offset;
  if (static_cast<uint64_t>(n_bytes) > available) {
    throw InputError(source, "data",
                     std::to_string(n_bytes) + " bytes for shape " + a.ShapeString(),
                     std::to_string(available) + " bytes (truncated file)");
  }
  a.data.assign(bytes.begin() + h.data_offset, bytes.begin() + h.data_offset + n_bytes);
  ToNativeCOrder(h.big_endian, h.fortran_order, &a);
  return a;
}

NdArray ReadNpyFile(const std::string& path) {
  return ParseNpy(ReadFileBytes(path, ".npy file"), path);
}

std::string SerializeNpy(const NdArray& a) {
  std::string dict = "{'descr': '" + DTypeDescr(a) + "', 'fortran_order': False, " +
                     "'shape': " + a.ShapeString() + ", }";
  // Pad with spaces so that the data starts at a multiple of 64 bytes, ending in '\n'.
  const bool v2 = dict.size() + 11 > 65535;
  const size_t prefix = v2 ? 12 : 10;
  const size_t total = (prefix + dict.size() + 1 + 63) / 64 * 64;
  dict.append(total - prefix - dict.size() - 1, ' ');
  dict.push_back('\n');
  std::string out(kMagic, kMagicSize);
  out.push_back(v2 ? 2 : 1);
  out.push_back(0);
  const size_t len = dict.size();
  out.push_back(static_cast<char>(len & 0xFF));
  out.push_back(static_cast<char>((len >> 8) & 0xFF));
  if (v2) {
    out.push_back(static_cast<char>((len >> 16) & 0xFF));
    out.push_back(static_cast<char>((len >> 24) & 0xFF));
  }
  out += dict;
  NdArray little = a;
  ToNativeCOrder(HostIsBigEndian(), false, &little);  // swaps on big-endian hosts only
  out.append(reinterpret_cast<const char*>(little.data.data()), little.data.size());
  return out;
}

void WriteNpyFile(const std::string& path, const NdArray& a) {
  std::ofstream out(path, std::ios::binary);
  const std::string bytes = SerializeNpy(a);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) throw InputError(path, "", "a writable file", "write failed");
}

}  // namespace handlabel
