#include "formats/pickle_writer.h"

#include <cstdint>

#include "core/errors.h"

namespace handlabel {
namespace {

// Pickle opcodes (Python's pickletools names).
constexpr char kProto = '\x80', kStop = '.', kMark = '(', kEmptyDict = '}',
               kSetItems = 'u', kGlobal = 'c', kReduce = 'R', kBuild = 'b', kTuple = 't',
               kTuple1 = '\x85', kTuple2 = '\x86', kTuple3 = '\x87', kNewTrue = '\x88',
               kNewFalse = '\x89', kNone = 'N', kBinInt = 'J', kBinUnicode = 'X';

class Writer {
 public:
  std::string Finish() { return out_ + kStop; }
  void Op(char op) { out_ += op; }
  void Proto2() { out_ += {kProto, '\x02'}; }
  void Int(int64_t v) {
    if (v < INT32_MIN || v > INT32_MAX) throw Error("pickle: integer out of range");
    Op(kBinInt);
    Le(static_cast<uint32_t>(static_cast<int32_t>(v)));
  }
  void Bool(bool v) { Op(v ? kNewTrue : kNewFalse); }
  void Text(const std::string& utf8) {
    Op(kBinUnicode);
    Le(static_cast<uint32_t>(utf8.size()));
    out_ += utf8;
  }
  void Global(const std::string& module, const std::string& name) {
    out_ += kGlobal + module + "\n" + name + "\n";
  }
  // Python 3's protocol-2 form of a bytes object: _codecs.encode(latin-1 text,
  // 'latin1'), the text UTF-8 encoded in the pickle.
  void Bytes(const uint8_t* data, size_t size) {
    Global("_codecs", "encode");
    std::string utf8;
    utf8.reserve(size + size / 2);
    for (size_t i = 0; i < size; ++i) {
      const uint8_t b = data[i];
      if (b < 0x80) {
        utf8 += static_cast<char>(b);
      } else {
        utf8 += static_cast<char>(0xC0 | (b >> 6));
        utf8 += static_cast<char>(0x80 | (b & 0x3F));
      }
    }
    Text(utf8);
    Text("latin1");
    Op(kTuple2);
    Op(kReduce);
  }

 private:
  void Le(uint32_t v) {
    for (int k = 0; k < 4; ++k) out_ += static_cast<char>((v >> (8 * k)) & 0xFF);
  }
  std::string out_;
};

// numpy's dtype string ("f8") and byte order character ('<', or '|' for one byte).
std::pair<std::string, std::string> Descr(const NdArray& a, const std::string& name) {
  switch (a.dtype) {
    case DType::kBool:
      return {"b1", "|"};
    case DType::kInt8:
      return {"i1", "|"};
    case DType::kUInt8:
      return {"u1", "|"};
    case DType::kInt16:
      return {"i2", "<"};
    case DType::kUInt16:
      return {"u2", "<"};
    case DType::kInt32:
      return {"i4", "<"};
    case DType::kUInt32:
      return {"u4", "<"};
    case DType::kInt64:
      return {"i8", "<"};
    case DType::kUInt64:
      return {"u8", "<"};
    case DType::kFloat16:
      return {"f2", "<"};
    case DType::kFloat32:
      return {"f4", "<"};
    case DType::kFloat64:
      return {"f8", "<"};
    default:
      throw Error("pickle: array '" + name + "' has dtype " + DTypeName(a.dtype) +
                  "; only numeric arrays are written");
  }
}

// ndarray.__reduce__: _reconstruct(ndarray, (0,), b'b'), then BUILD with
// (1, shape, dtype, is_fortran, data).
void WriteArray(const NdArray& a, const std::string& name, Writer* w) {
  const auto [descr, order] = Descr(a, name);
  w->Global("numpy.core.multiarray", "_reconstruct");
  w->Global("numpy", "ndarray");
  w->Int(0);
  w->Op(kTuple1);
  const uint8_t b = 'b';
  w->Bytes(&b, 1);
  w->Op(kTuple3);
  w->Op(kReduce);
  w->Op(kMark);
  w->Int(1);
  w->Op(kMark);
  for (const int64_t d : a.shape) w->Int(d);
  w->Op(kTuple);
  // numpy.dtype(descr, False, True), then its state (3, order, None, None, None, -1,
  // -1, 0).
  w->Global("numpy", "dtype");
  w->Text(descr);
  w->Bool(false);
  w->Bool(true);
  w->Op(kTuple3);
  w->Op(kReduce);
  w->Op(kMark);
  w->Int(3);
  w->Text(order);
  w->Op(kNone);
  w->Op(kNone);
  w->Op(kNone);
  w->Int(-1);
  w->Int(-1);
  w->Int(0);
  w->Op(kTuple);
  w->Op(kBuild);
  w->Bool(false);  // C order
  w->Bytes(a.data.data(), a.data.size());
  w->Op(kTuple);
  w->Op(kBuild);
}

}  // namespace

std::string PickleArrayDict(const NamedArrays& arrays) {
  Writer w;
  w.Proto2();
  w.Op(kEmptyDict);
  w.Op(kMark);
  for (const auto& [name, array] : arrays) {
    w.Text(name);
    WriteArray(array, name, &w);
  }
  w.Op(kSetItems);
  return w.Finish();
}

}  // namespace handlabel
