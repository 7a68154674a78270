#pragma once
// A typed n-dimensional array as read from .npy files, pickles and torch archives:
// a dtype, a shape and the elements in C (row-major) order, native byte order.
// Readers convert Fortran order and foreign byte order on the way in, so consumers
// only ever see one layout.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

enum class DType {
  kBool,
  kInt8,
  kUInt8,
  kInt16,
  kUInt16,
  kInt32,
  kUInt32,
  kInt64,
  kUInt64,
  kFloat16,
  kFloat32,
  kFloat64,
  kUnicode,  // numpy 'U<n>': n UCS-4 code points per element (itemsize 4n)
  kBytes,    // numpy 'S<n>': n bytes per element, NUL padded
};

// Element size in bytes of the fixed-size dtypes; 0 for kUnicode / kBytes, whose
// size is part of the array (NdArray::itemsize).
int FixedDTypeSize(DType dtype);
// numpy's name: "float64", "int32", "bool", "str", "bytes", ...
const char* DTypeName(DType dtype);
bool IsNumeric(DType dtype);

struct NdArray {
  DType dtype = DType::kFloat64;
  int64_t itemsize = 8;        // bytes per element
  std::vector<int64_t> shape;  // empty = 0-d scalar
  std::vector<uint8_t> data;   // size() * itemsize bytes, C order, native endian

  // Number of elements (1 for a 0-d array). Shapes are validated on construction by
  // every reader, so this cannot overflow.
  int64_t size() const;
  int ndim() const { return static_cast<int>(shape.size()); }
  std::string ShapeString() const;  // "(778, 3)"

  // Elements converted to double / int64 (numeric dtypes only; throws Error otherwise).
  std::vector<double> ToDoubles() const;
  std::vector<int64_t> ToInt64s() const;
  // The text of a 0-d or 1-element kUnicode / kBytes array (UTF-8, trailing NULs cut).
  std::string ToText() const;

  // Builders (C order).
  static NdArray FromDoubles(const std::vector<int64_t>& shape, const double* values);
  // float32, each value rounded to nearest (what datasets such as DexYCB store).
  static NdArray FromDoublesAsFloat32(const std::vector<int64_t>& shape,
                                      const double* values);
  static NdArray FromInt64s(const std::vector<int64_t>& shape, const int64_t* values,
                            DType dtype = DType::kInt64);
  static NdArray FromText(const std::string& utf8);  // 0-d numpy 'U<n>' array
  // 1-d numpy 'U<n>' array, n = the longest text's code points (at least 1).
  static NdArray FromTexts(const std::vector<std::string>& utf8);
  // Row-major copy of any Eigen matrix of doubles, shape (rows, cols).
  static NdArray FromMatrix(const Eigen::MatrixXd& m);
};

// Checked product of a shape's dimensions times itemsize; throws Error naming `what`
// when a dimension is negative or the byte count exceeds max_bytes.
int64_t CheckedByteCount(const std::vector<int64_t>& shape, int64_t itemsize,
                         int64_t max_bytes, const std::string& what);

// IEEE half -> double (exact).
double HalfToDouble(uint16_t h);

}  // namespace handlabel
