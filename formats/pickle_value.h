#pragma once
// The plain data a restricted pickle decodes to (see pickle_reader.h): None, bools,
// ints, floats, text, bytes, lists (list / tuple / set), dicts, numpy arrays, scipy
// sparse matrices and references to torch tensors. Class instances the reader
// understands are already reduced to these (a chumpy Ch to its array, a chumpy Select
// to a.ravel()[idxs].reshape(preferred_shape), a csc_matrix to kSparse).

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "formats/nd_array.h"

namespace handlabel {

// A scipy.sparse compressed matrix as pickled: format "csc" or "csr"; for csc,
// indptr has cols + 1 entries and indices are row numbers (csr: the transpose).
struct SparseArrays {
  std::string format;
  int64_t rows = 0;
  int64_t cols = 0;
  NdArray data;
  NdArray indices;
  NdArray indptr;
};

// A tensor inside a torch.save archive: its elements live in the archive entry
// "<archive>/data/<storage_key>" (see torch_archive.h).
struct TensorRef {
  std::string storage_key;
  std::string device;  // "cpu", "cuda:0", ... (as saved)
  DType dtype = DType::kFloat32;
  int64_t storage_numel = 0;  // elements in the storage
  int64_t storage_offset = 0;
  std::vector<int64_t> shape;
  std::vector<int64_t> stride;  // in elements
};

struct PickleValue {
  enum class Kind {
    kNone,
    kBool,
    kInt,
    kFloat,
    kText,   // UTF-8 (Python 3 str; Python 2 str decoded as Latin-1)
    kBytes,  // Python 3 bytes / bytearray
    kList,   // list, tuple, set, frozenset
    kDict,   // dict, OrderedDict (insertion order kept)
    kArray,
    kSparse,
    kTensor,
    kUnsupported,  // understood but not representable (object arrays, ...): `text` says
  };
  Kind kind = Kind::kNone;
  std::string type_name;  // Python type, for messages: "tuple", "chumpy.ch.Ch", ...
  bool boolean = false;
  int64_t integer = 0;
  double real = 0;
  std::string text;
  std::vector<PickleValue> items;
  std::vector<std::pair<PickleValue, PickleValue>> entries;
  std::shared_ptr<const NdArray> array;
  std::shared_ptr<const SparseArrays> sparse;
  std::shared_ptr<const TensorRef> tensor;

  bool is_number() const {
    return kind == Kind::kBool || kind == Kind::kInt || kind == Kind::kFloat;
  }
  double number() const {
    return kind == Kind::kFloat ? real : kind == Kind::kInt ? integer : boolean;
  }
  // The value of a dict entry whose key is the text `key`, or nullptr.
  const PickleValue* Find(const std::string& key) const;
  // "dict with 12 entries", "float64 array (778, 3)", ... for error messages.
  std::string Describe() const;
};

}  // namespace handlabel
