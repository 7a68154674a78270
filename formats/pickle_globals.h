#pragma once
// The Python globals the restricted pickle reader (pickle_reader.h) understands, and
// the names of pickle opcodes for its error messages. Everything not listed here is
// refused by the reader.

#include <cstdint>
#include <string>

#include "formats/nd_array.h"

namespace handlabel::pickle {

// The callables and classes the reader understands. Anything else is refused.
enum class Global {
  kNdarray,
  kReconstruct,
  kDTypeClass,
  kScalar,
  kFromBuffer,
  kSet,
  kFrozenSet,
  kBytesClass,
  kBytearray,
  kObjectClass,
  kCodecsEncode,
  kCopyregReconstructor,
  kOrderedDict,
  kCh,
  kSelect,
  kCscMatrix,
  kCsrMatrix,
  kRebuildTensorV2,
  kRebuildParameter,
  kStorage,
  kLoadFromBytes,  // torch.storage._load_from_bytes: a storage saved inside the pickle
};

// Finds module.name (numpy.core and numpy._core, __builtin__ and builtins alike).
// storage_dtype is the element type of torch storage classes.
bool LookupPickleGlobal(const std::string& module, const std::string& name,
                        Global* global, DType* storage_dtype);

// Classes whose instances the reader can build (NEWOBJ / REDUCE / INST / OBJ) and fill
// from BUILD state.
bool IsInstanceClass(Global g);

// "GLOBAL", "BINSTRING", ...; nullptr for a byte that is no opcode.
const char* PickleOpcodeName(uint8_t op);

}  // namespace handlabel::pickle
