#pragma once
// A restricted reader for Python pickles (protocols 0-5, including the Python 2 forms
// of the official MANO files). It runs no Python and calls nothing: it understands
// the opcodes and the few globals that numpy arrays, chumpy Ch / Select objects,
// scipy sparse matrices, OrderedDicts and torch.save tensors need, builds plain data
// (pickle_value.h) from them, and rejects every other global or opcode with an
// InputError naming the source, the opcode or global and its byte offset.
//
// Understood globals (numpy.core.* and numpy._core.* alike; __builtin__ and builtins):
//   numpy.core.multiarray._reconstruct, numpy.ndarray, numpy.dtype,
//   numpy.core.multiarray.scalar, numpy.core.numeric._frombuffer,
//   builtins.set / frozenset / bytes / bytearray / object, _codecs.encode,
//   copy_reg._reconstructor, collections.OrderedDict, chumpy.ch.Ch,
//   chumpy.reordering.Select, scipy.sparse.{csc,_csc,csr,_csr}.{csc,csr}_matrix,
//   torch._utils._rebuild_tensor_v2 / _rebuild_parameter, torch.<Type>Storage,
//   torch.storage._load_from_bytes.
// Tensors: inside a torch.save archive they stay references (kTensor, read through
// torch_archive.h); a tensor pickled with plain pickle carries its storage as
// _load_from_bytes(<torch.save bytes>) (legacy or zip form), which is decoded here:
// such a tensor becomes a plain array (kArray, C order), after checking the stored
// element count against the bytes present and the view's offset and strides against
// the storage. Nothing else of torch.save is accepted.
// Limits: every length is checked against the bytes left before anything is
// allocated; the number of values, the container nesting depth and the total bytes
// of decoded arrays are capped (PickleLimits).

#include <cstdint>
#include <string>

#include "formats/pickle_value.h"

namespace handlabel {

struct PickleLimits {
  int64_t max_values = int64_t{1} << 22;       // objects created while reading
  int max_depth = 64;                          // nesting of containers and objects
  int64_t max_total_bytes = int64_t{4} << 30;  // decoded array and string payload
  // Throws InputError naming `source` (the pickle) and the field.
  void Check(const std::string& source) const;
};

// Decodes one pickle. `source` names the file (and archive entry) in errors.
PickleValue ReadPickle(const std::string& bytes, const std::string& source,
                       const PickleLimits& limits = {});
PickleValue ReadPickleFile(const std::string& path, const PickleLimits& limits = {});

}  // namespace handlabel
