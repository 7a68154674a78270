#include "formats/nd_array.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

#include "core/errors.h"
#include "formats/utf8.h"

namespace handlabel {
namespace {

template <typename T>
T LoadAs(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

// Calls f(double-or-int64 value) for every element of a numeric array.
template <typename Out>
std::vector<Out> Convert(const NdArray& a) {
  const int64_t n = a.size();
  std::vector<Out> out(static_cast<size_t>(n));
  const uint8_t* p = a.data.data();
  for (int64_t i = 0; i < n; ++i, p += a.itemsize) {
    switch (a.dtype) {
      case DType::kBool:
        out[i] = static_cast<Out>(*p != 0);
        break;
      case DType::kInt8:
        out[i] = static_cast<Out>(LoadAs<int8_t>(p));
        break;
      case DType::kUInt8:
        out[i] = static_cast<Out>(*p);
        break;
      case DType::kInt16:
        out[i] = static_cast<Out>(LoadAs<int16_t>(p));
        break;
      case DType::kUInt16:
        out[i] = static_cast<Out>(LoadAs<uint16_t>(p));
        break;
      case DType::kInt32:
        out[i] = static_cast<Out>(LoadAs<int32_t>(p));
        break;
      case DType::kUInt32:
        out[i] = static_cast<Out>(LoadAs<uint32_t>(p));
        break;
      case DType::kInt64:
        out[i] = static_cast<Out>(LoadAs<int64_t>(p));
        break;
      case DType::kUInt64:
        out[i] = static_cast<Out>(LoadAs<uint64_t>(p));
        break;
      case DType::kFloat16:
        out[i] = static_cast<Out>(HalfToDouble(LoadAs<uint16_t>(p)));
        break;
      case DType::kFloat32:
        out[i] = static_cast<Out>(LoadAs<float>(p));
        break;
      case DType::kFloat64:
        out[i] = static_cast<Out>(LoadAs<double>(p));
        break;
      default:
        throw Error(std::string("cannot convert a ") + DTypeName(a.dtype) +
                    " array to numbers");
    }
  }
  return out;
}

}  // namespace

int FixedDTypeSize(DType dtype) {
  switch (dtype) {
    case DType::kBool:
    case DType::kInt8:
    case DType::kUInt8:
      return 1;
    case DType::kInt16:
    case DType::kUInt16:
    case DType::kFloat16:
      return 2;
    case DType::kInt32:
    case DType::kUInt32:
    case DType::kFloat32:
      return 4;
    case DType::kInt64:
    case DType::kUInt64:
    case DType::kFloat64:
      return 8;
    case DType::kUnicode:
    case DType::kBytes:
      return 0;
  }
  return 0;
}

const char* DTypeName(DType dtype) {
  switch (dtype) {
    case DType::kBool:
      return "bool";
    case DType::kInt8:
      return "int8";
    case DType::kUInt8:
      return "uint8";
    case DType::kInt16:
      return "int16";
    case DType::kUInt16:
      return "uint16";
    case DType::kInt32:
      return "int32";
    case DType::kUInt32:
      return "uint32";
    case DType::kInt64:
      return "int64";
    case DType::kUInt64:
      return "uint64";
    case DType::kFloat16:
      return "float16";
    case DType::kFloat32:
      return "float32";
    case DType::kFloat64:
      return "float64";
    case DType::kUnicode:
      return "str";
    case DType::kBytes:
      return "bytes";
  }
  return "?";
}

bool IsNumeric(DType dtype) { return dtype != DType::kUnicode && dtype != DType::kBytes; }

int64_t NdArray::size() const {
  int64_t n = 1;
  for (int64_t d : shape) n *= d;
  return n;
}

std::string NdArray::ShapeString() const {
  std::string s = "(";
  for (size_t i = 0; i < shape.size(); ++i) {
    if (i) s += ", ";
    s += std::to_string(shape[i]);
  }
  if (shape.size() == 1) s += ",";
  return s + ")";
}

std::vector<double> NdArray::ToDoubles() const { return Convert<double>(*this); }
std::vector<int64_t> NdArray::ToInt64s() const {
  if (dtype == DType::kFloat16 || dtype == DType::kFloat32 || dtype == DType::kFloat64) {
    throw Error(std::string("expected an integer array, got ") + DTypeName(dtype));
  }
  return Convert<int64_t>(*this);
}

std::string NdArray::ToText() const {
  if (size() != 1 || IsNumeric(dtype)) {
    throw Error("expected a single string, got a " + std::string(DTypeName(dtype)) +
                " array of shape " + ShapeString());
  }
  std::string out;
  if (dtype == DType::kBytes) {
    out.assign(data.begin(), data.end());
  } else {
    for (int64_t i = 0; i + 4 <= itemsize; i += 4) {
      const uint32_t c = LoadAs<uint32_t>(data.data() + i);
      if (c == 0) break;
      AppendUtf8(c, &out);
    }
  }
  while (!out.empty() && out.back() == '\0') out.pop_back();
  return out;
}

NdArray NdArray::FromDoubles(const std::vector<int64_t>& shape, const double* values) {
  NdArray a;
  a.dtype = DType::kFloat64;
  a.itemsize = 8;
  a.shape = shape;
  a.data.resize(static_cast<size_t>(a.size()) * 8);
  if (!a.data.empty()) std::memcpy(a.data.data(), values, a.data.size());
  return a;
}

NdArray NdArray::FromDoublesAsFloat32(const std::vector<int64_t>& shape,
                                      const double* values) {
  NdArray a;
  a.dtype = DType::kFloat32;
  a.itemsize = 4;
  a.shape = shape;
  const int64_t n = a.size();
  a.data.resize(static_cast<size_t>(n) * 4);
  for (int64_t i = 0; i < n; ++i) {
    const float f = static_cast<float>(values[i]);
    std::memcpy(a.data.data() + 4 * i, &f, 4);
  }
  return a;
}

NdArray NdArray::FromInt64s(const std::vector<int64_t>& shape, const int64_t* values,
                            DType dtype) {
  NdArray a;
  a.dtype = dtype;
  a.itemsize = FixedDTypeSize(dtype);
  a.shape = shape;
  const int64_t n = a.size();
  a.data.resize(static_cast<size_t>(n * a.itemsize));
  for (int64_t i = 0; i < n; ++i) {
    uint8_t* p = a.data.data() + i * a.itemsize;
    const int64_t v = values[i];
    switch (dtype) {
      case DType::kBool:
        *p = v != 0;
        break;
      case DType::kInt8:
      case DType::kUInt8:
        *p = static_cast<uint8_t>(v);
        break;
      case DType::kInt16:
      case DType::kUInt16: {
        const uint16_t x = static_cast<uint16_t>(v);
        std::memcpy(p, &x, 2);
        break;
      }
      case DType::kInt32:
      case DType::kUInt32: {
        const uint32_t x = static_cast<uint32_t>(v);
        std::memcpy(p, &x, 4);
        break;
      }
      case DType::kInt64:
      case DType::kUInt64:
        std::memcpy(p, &v, 8);
        break;
      default:
        throw Error("FromInt64s needs an integer dtype");
    }
  }
  return a;
}

NdArray NdArray::FromText(const std::string& utf8) {
  NdArray a = FromTexts({utf8});
  a.shape.clear();  // 0-d
  return a;
}

NdArray NdArray::FromTexts(const std::vector<std::string>& utf8) {
  std::vector<std::vector<uint32_t>> cps;
  size_t longest = 1;  // numpy's narrowest string dtype is 'U1'
  for (const std::string& s : utf8) {
    cps.push_back(DecodeUtf8(s));
    longest = std::max(longest, cps.back().size());
  }
  NdArray a;
  a.dtype = DType::kUnicode;
  a.itemsize = 4 * static_cast<int64_t>(longest);
  a.shape = {static_cast<int64_t>(utf8.size())};
  a.data.assign(static_cast<size_t>(a.itemsize) * utf8.size(), 0);
  for (size_t i = 0; i < cps.size(); ++i) {
    if (!cps[i].empty())
      std::memcpy(a.data.data() + i * a.itemsize, cps[i].data(), 4 * cps[i].size());
  }
  return a;
}

NdArray NdArray::FromMatrix(const Eigen::MatrixXd& m) {
  const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> r = m;
  return FromDoubles({r.rows(), r.cols()}, r.data());
}

int64_t CheckedByteCount(const std::vector<int64_t>& shape, int64_t itemsize,
                         int64_t max_bytes, const std::string& what) {
  if (itemsize < 0 || itemsize > max_bytes) {
    throw Error(what + ": element size " + std::to_string(itemsize) + " out of range");
  }
  int64_t count = 1;
  bool zero = false;
  for (int64_t d : shape) {
    if (d < 0) throw Error(what + ": negative dimension " + std::to_string(d));
    if (d == 0) zero = true;
  }
  if (zero) return 0;
  for (int64_t d : shape) {
    if (count > max_bytes / d) {
      throw Error(what + ": declared size exceeds the limit of " +
                  std::to_string(max_bytes) + " bytes");
    }
    count *= d;
  }
  if (itemsize != 0 && count > max_bytes / itemsize) {
    throw Error(what + ": declared size exceeds the limit of " +
                std::to_string(max_bytes) + " bytes");
  }
  return count * itemsize;
}

double HalfToDouble(uint16_t h) {
  const int sign = (h >> 15) & 1;
  const int exponent = (h >> 10) & 0x1F;
  const int mantissa = h & 0x3FF;
  double v;
  if (exponent == 0) {
    v = std::ldexp(static_cast<double>(mantissa), -24);
  } else if (exponent == 31) {
    v = mantissa ? std::numeric_limits<double>::quiet_NaN()
                 : std::numeric_limits<double>::infinity();
  } else {
    v = std::ldexp(static_cast<double>(mantissa | 0x400), exponent - 25);
  }
  return sign ? -v : v;
}

}  // namespace handlabel
