#pragma once
// numpy .npy files (format versions 1.0, 2.0 and 3.0): little or big endian, C or
// Fortran order, bool / int / uint / float16/32/64 and fixed-width str / bytes.
// Reading returns an NdArray in C order and native byte order. Object arrays
// ('|O', whose payload is a pickle) are recognised by ParseNpyHeader but not decoded
// here; see hand_model_io.cc for the one place that accepts them.
// Format: https://numpy.org/doc/stable/reference/generated/numpy.lib.format.html

#include <cstdint>
#include <string>

#include "formats/nd_array.h"

namespace handlabel {

// Default ceiling on the bytes one array may declare (a guard against hostile
// headers; real hand models are a few MB, network checkpoints a few hundred).
constexpr int64_t kDefaultMaxArrayBytes = int64_t{4} << 30;

struct NpyHeader {
  std::string descr;  // numpy's dtype string, e.g. "<f8"
  bool is_object = false;
  DType dtype = DType::kFloat64;
  int64_t itemsize = 8;
  bool big_endian = false;
  bool fortran_order = false;
  std::vector<int64_t> shape;
  size_t data_offset = 0;  // where the elements start
};

// Parses a dtype descriptor ('<f8', '>i4', '|b1', '<U5', '|S3', '=f4'; a leading
// '=' or '|' means native / not applicable). Returns false for anything else
// (structured, object, datetime, complex).
bool ParseDTypeDescr(const std::string& descr, DType* dtype, int64_t* itemsize,
                     bool* big_endian);
// The '<'-prefixed descriptor numpy writes for `a` ("<f8", "|u1", "<U5").
std::string DTypeDescr(const NdArray& a);

// Turns elements stored big endian and/or in Fortran order into native C order.
void ToNativeCOrder(bool big_endian, bool fortran_order, NdArray* a);

// `source` names the file (and entry) in error messages.
NpyHeader ParseNpyHeader(const std::string& bytes, const std::string& source);
NdArray ParseNpy(const std::string& bytes, const std::string& source,
                 int64_t max_bytes = kDefaultMaxArrayBytes);
NdArray ReadNpyFile(const std::string& path);

// Writes format 1.0 (2.0 when the header does not fit), little endian, C order.
std::string SerializeNpy(const NdArray& a);
void WriteNpyFile(const std::string& path, const NdArray& a);

}  // namespace handlabel
