#include "core/pickle_globals.h"

namespace handlabel::pickle {
namespace {

struct KnownGlobal {
  const char* module;
  const char* name;
  Global global;
  DType storage_dtype;
};

constexpr KnownGlobal kKnownGlobals[] = {
    {"numpy", "ndarray", Global::kNdarray, DType::kUInt8},
    {"numpy", "dtype", Global::kDTypeClass, DType::kUInt8},
    {"numpy.core.multiarray", "_reconstruct", Global::kReconstruct, DType::kUInt8},
    {"numpy._core.multiarray", "_reconstruct", Global::kReconstruct, DType::kUInt8},
    {"numpy.core.multiarray", "scalar", Global::kScalar, DType::kUInt8},
    {"numpy._core.multiarray", "scalar", Global::kScalar, DType::kUInt8},
    {"numpy.core.numeric", "_frombuffer", Global::kFromBuffer, DType::kUInt8},
    {"numpy._core.numeric", "_frombuffer", Global::kFromBuffer, DType::kUInt8},
    {"__builtin__", "set", Global::kSet, DType::kUInt8},
    {"builtins", "set", Global::kSet, DType::kUInt8},
    {"__builtin__", "frozenset", Global::kFrozenSet, DType::kUInt8},
    {"builtins", "frozenset", Global::kFrozenSet, DType::kUInt8},
    {"__builtin__", "bytes", Global::kBytesClass, DType::kUInt8},
    {"builtins", "bytes", Global::kBytesClass, DType::kUInt8},
    {"__builtin__", "bytearray", Global::kBytearray, DType::kUInt8},
    {"builtins", "bytearray", Global::kBytearray, DType::kUInt8},
    {"__builtin__", "object", Global::kObjectClass, DType::kUInt8},
    {"builtins", "object", Global::kObjectClass, DType::kUInt8},
    {"_codecs", "encode", Global::kCodecsEncode, DType::kUInt8},
    {"copy_reg", "_reconstructor", Global::kCopyregReconstructor, DType::kUInt8},
    {"copyreg", "_reconstructor", Global::kCopyregReconstructor, DType::kUInt8},
    {"collections", "OrderedDict", Global::kOrderedDict, DType::kUInt8},
    {"chumpy.ch", "Ch", Global::kCh, DType::kUInt8},
    {"chumpy.reordering", "Select", Global::kSelect, DType::kUInt8},
    {"scipy.sparse.csc", "csc_matrix", Global::kCscMatrix, DType::kUInt8},
    {"scipy.sparse._csc", "csc_matrix", Global::kCscMatrix, DType::kUInt8},
    {"scipy.sparse", "csc_matrix", Global::kCscMatrix, DType::kUInt8},
    {"scipy.sparse.csr", "csr_matrix", Global::kCsrMatrix, DType::kUInt8},
    {"scipy.sparse._csr", "csr_matrix", Global::kCsrMatrix, DType::kUInt8},
    {"scipy.sparse", "csr_matrix", Global::kCsrMatrix, DType::kUInt8},
    {"torch._utils", "_rebuild_tensor_v2", Global::kRebuildTensorV2, DType::kUInt8},
    {"torch._utils", "_rebuild_parameter", Global::kRebuildParameter, DType::kUInt8},
    {"torch", "FloatStorage", Global::kStorage, DType::kFloat32},
    {"torch", "DoubleStorage", Global::kStorage, DType::kFloat64},
    {"torch", "HalfStorage", Global::kStorage, DType::kFloat16},
    {"torch", "LongStorage", Global::kStorage, DType::kInt64},
    {"torch", "IntStorage", Global::kStorage, DType::kInt32},
    {"torch", "ShortStorage", Global::kStorage, DType::kInt16},
    {"torch", "CharStorage", Global::kStorage, DType::kInt8},
    {"torch", "ByteStorage", Global::kStorage, DType::kUInt8},
    {"torch", "BoolStorage", Global::kStorage, DType::kBool},
};

}  // namespace

bool LookupPickleGlobal(const std::string& module, const std::string& name,
                        Global* global, DType* storage_dtype) {
  for (const KnownGlobal& k : kKnownGlobals) {
    if (module == k.module && name == k.name) {
      *global = k.global;
      *storage_dtype = k.storage_dtype;
      return true;
    }
  }
  return false;
}

bool IsInstanceClass(Global g) {
  return g == Global::kCh || g == Global::kSelect || g == Global::kCscMatrix ||
         g == Global::kCsrMatrix || g == Global::kOrderedDict;
}

const char* PickleOpcodeName(uint8_t op) {
  switch (op) {
    case '(':
      return "MARK";
    case '.':
      return "STOP";
    case '0':
      return "POP";
    case '1':
      return "POP_MARK";
    case '2':
      return "DUP";
    case 'F':
      return "FLOAT";
    case 'I':
      return "INT";
    case 'J':
      return "BININT";
    case 'K':
      return "BININT1";
    case 'L':
      return "LONG";
    case 'M':
      return "BININT2";
    case 'N':
      return "NONE";
    case 'P':
      return "PERSID";
    case 'Q':
      return "BINPERSID";
    case 'R':
      return "REDUCE";
    case 'S':
      return "STRING";
    case 'T':
      return "BINSTRING";
    case 'U':
      return "SHORT_BINSTRING";
    case 'V':
      return "UNICODE";
    case 'X':
      return "BINUNICODE";
    case 'a':
      return "APPEND";
    case 'b':
      return "BUILD";
    case 'c':
      return "GLOBAL";
    case 'd':
      return "DICT";
    case '}':
      return "EMPTY_DICT";
    case 'e':
      return "APPENDS";
    case 'g':
      return "GET";
    case 'h':
      return "BINGET";
    case 'i':
      return "INST";
    case 'j':
      return "LONG_BINGET";
    case 'l':
      return "LIST";
    case ']':
      return "EMPTY_LIST";
    case 'o':
      return "OBJ";
    case 'p':
      return "PUT";
    case 'q':
      return "BINPUT";
    case 'r':
      return "LONG_BINPUT";
    case 's':
      return "SETITEM";
    case 't':
      return "TUPLE";
    case ')':
      return "EMPTY_TUPLE";
    case 'u':
      return "SETITEMS";
    case 'G':
      return "BINFLOAT";
    case 0x80:
      return "PROTO";
    case 0x81:
      return "NEWOBJ";
    case 0x82:
      return "EXT1";
    case 0x83:
      return "EXT2";
    case 0x84:
      return "EXT4";
    case 0x85:
      return "TUPLE1";
    case 0x86:
      return "TUPLE2";
    case 0x87:
      return "TUPLE3";
    case 0x88:
      return "NEWTRUE";
    case 0x89:
      return "NEWFALSE";
    case 0x8a:
      return "LONG1";
    case 0x8b:
      return "LONG4";
    case 'B':
      return "BINBYTES";
    case 'C':
      return "SHORT_BINBYTES";
    case 0x8c:
      return "SHORT_BINUNICODE";
    case 0x8d:
      return "BINUNICODE8";
    case 0x8e:
      return "BINBYTES8";
    case 0x8f:
      return "EMPTY_SET";
    case 0x90:
      return "ADDITEMS";
    case 0x91:
      return "FROZENSET";
    case 0x92:
      return "NEWOBJ_EX";
    case 0x93:
      return "STACK_GLOBAL";
    case 0x94:
      return "MEMOIZE";
    case 0x95:
      return "FRAME";
    case 0x96:
      return "BYTEARRAY8";
    case 0x97:
      return "NEXT_BUFFER";
    case 0x98:
      return "READONLY_BUFFER";
  }
  return nullptr;
}

}  // namespace handlabel::pickle
