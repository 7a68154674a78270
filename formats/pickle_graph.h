#pragma once
// Internal to the restricted pickle reader (pickle_reader.h): the object graph its
// opcode machine builds, and the conversion of that graph into plain PickleValues.
// Nodes refer to each other by index, so shared and cyclic references cost nothing
// while reading; the conversion bounds depth and size.

#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "formats/nd_array.h"
#include "formats/pickle_globals.h"
#include "formats/pickle_reader.h"

namespace handlabel::pickle {

// Values while reading. Ids index the node vector; containers refer to children by id,
// so shared and even cyclic references cost nothing and never recurse here.
enum class NodeKind {
  kNone,
  kBool,
  kInt,
  kFloat,
  kText,
  kBytes,
  kPy2Str,  // Python 2 str: raw bytes, Latin-1 when read as text
  kList,
  kTuple,
  kSet,
  kDict,
  kGlobal,
  kObject,        // instance of an understood class: attributes in `entries`
  kPendingArray,  // numpy _reconstruct result awaiting its BUILD state
  kArray,
  kDType,
  kStorage,
  kTensor,
  kUnsupported,
};

struct Node {
  NodeKind kind = NodeKind::kNone;
  int depth = 0;  // container nesting below and including this node
  bool boolean = false;
  int64_t integer = 0;
  double real = 0;
  std::string text;  // text (UTF-8), bytes, Python 2 str, unsupported reason
  std::vector<int> items;
  std::vector<std::pair<int, int>> entries;
  Global global = Global::kObjectClass;
  std::string global_name;  // "module.name" of a global or an instance's class
  std::shared_ptr<NdArray> array;
  // dtype (kDType, kStorage): element type; supported = false for object/structured.
  DType dtype = DType::kFloat64;
  int64_t itemsize = 8;
  bool big_endian = false;
  bool dtype_supported = true;
  std::shared_ptr<TensorRef> tensor;  // kStorage, kTensor
};

// "a tuple", "global numpy.dtype", ... for error messages.
std::string DescribeNode(const Node& n);

// Converts node `root` and everything it refers to. Chumpy Ch / Select objects become
// arrays, scipy matrices kSparse; errors are InputErrors naming `source` and the
// object's field; depth and the number of produced values are bounded by `limits`.
PickleValue ConvertPickleGraph(const std::vector<Node>& nodes, int root,
                               const std::string& source, const PickleLimits& limits);

}  // namespace handlabel::pickle
