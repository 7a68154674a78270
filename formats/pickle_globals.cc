#include "formats/pickle_globals.h"

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
    {"torch.storage", "_load_from_bytes", Global::kLoadFromBytes, DType::kUInt8},
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

namespace {

struct OpcodeName {
  uint8_t op;
  const char* name;
};

// Every opcode of pickle protocols 0-5, as Python's pickletools names them.
constexpr OpcodeName kOpcodeNames[] = {
    {'(', "MARK"},
    {'.', "STOP"},
    {'0', "POP"},
    {'1', "POP_MARK"},
    {'2', "DUP"},
    {'F', "FLOAT"},
    {'I', "INT"},
    {'J', "BININT"},
    {'K', "BININT1"},
    {'L', "LONG"},
    {'M', "BININT2"},
    {'N', "NONE"},
    {'P', "PERSID"},
    {'Q', "BINPERSID"},
    {'R', "REDUCE"},
    {'S', "STRING"},
    {'T', "BINSTRING"},
    {'U', "SHORT_BINSTRING"},
    {'V', "UNICODE"},
    {'X', "BINUNICODE"},
    {'a', "APPEND"},
    {'b', "BUILD"},
    {'c', "GLOBAL"},
    {'d', "DICT"},
    {'}', "EMPTY_DICT"},
    {'e', "APPENDS"},
    {'g', "GET"},
    {'h', "BINGET"},
    {'i', "INST"},
    {'j', "LONG_BINGET"},
    {'l', "LIST"},
    {']', "EMPTY_LIST"},
    {'o', "OBJ"},
    {'p', "PUT"},
    {'q', "BINPUT"},
    {'r', "LONG_BINPUT"},
    {'s', "SETITEM"},
    {'t', "TUPLE"},
    {')', "EMPTY_TUPLE"},
    {'u', "SETITEMS"},
    {'G', "BINFLOAT"},
    {0x80, "PROTO"},
    {0x81, "NEWOBJ"},
    {0x82, "EXT1"},
    {0x83, "EXT2"},
    {0x84, "EXT4"},
    {0x85, "TUPLE1"},
    {0x86, "TUPLE2"},
    {0x87, "TUPLE3"},
    {0x88, "NEWTRUE"},
    {0x89, "NEWFALSE"},
    {0x8a, "LONG1"},
    {0x8b, "LONG4"},
    {'B', "BINBYTES"},
    {'C', "SHORT_BINBYTES"},
    {0x8c, "SHORT_BINUNICODE"},
    {0x8d, "BINUNICODE8"},
    {0x8e, "BINBYTES8"},
    {0x8f, "EMPTY_SET"},
    {0x90, "ADDITEMS"},
    {0x91, "FROZENSET"},
    {0x92, "NEWOBJ_EX"},
    {0x93, "STACK_GLOBAL"},
    {0x94, "MEMOIZE"},
    {0x95, "FRAME"},
    {0x96, "BYTEARRAY8"},
    {0x97, "NEXT_BUFFER"},
    {0x98, "READONLY_BUFFER"},
};

}  // namespace

const char* PickleOpcodeName(uint8_t op) {
  for (const OpcodeName& entry : kOpcodeNames) {
    if (entry.op == op) return entry.name;
  }
  return nullptr;
}

}  // namespace handlabel::pickle
