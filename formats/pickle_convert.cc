// Conversion of the pickle reader's object graph into plain PickleValues (see
// pickle_graph.h): chumpy Ch / Select objects to arrays, scipy matrices to kSparse.

#include <cstring>

#include "core/errors.h"
#include "formats/pickle_graph.h"
#include "formats/utf8.h"

namespace handlabel::pickle {

std::string DescribeNode(const Node& n) {
  switch (n.kind) {
    case NodeKind::kNone:
      return "None";
    case NodeKind::kBool:
      return "a bool";
    case NodeKind::kInt:
      return "an int";
    case NodeKind::kFloat:
      return "a float";
    case NodeKind::kText:
      return "a str";
    case NodeKind::kBytes:
      return "bytes";
    case NodeKind::kPy2Str:
      return "a Python 2 str";
    case NodeKind::kList:
      return "a list";
    case NodeKind::kTuple:
      return "a tuple";
    case NodeKind::kSet:
      return "a set";
    case NodeKind::kDict:
      return "a dict";
    case NodeKind::kGlobal:
      return "global " + n.global_name;
    case NodeKind::kObject:
      return "a " + n.global_name + " object";
    case NodeKind::kPendingArray:
      return "an ndarray without state";
    case NodeKind::kArray:
      return "an ndarray";
    case NodeKind::kDType:
      return "a numpy dtype";
    case NodeKind::kStorage:
      return "a torch storage";
    case NodeKind::kTensor:
      return "a torch tensor";
    case NodeKind::kUnsupported:
      return "unsupported " + n.global_name;
  }
  return "?";
}

namespace {

class Converter {
 public:
  Converter(const std::vector<Node>& nodes, const std::string& source,
            const PickleLimits& limits)
      : nodes_(nodes), source_(source), limits_(limits) {}

  void Budget(int depth) {
    if (depth > limits_.max_depth) {
      FailConvert("pickle",
                  "nesting at most " + std::to_string(limits_.max_depth) +
                      " levels deep (or a reference cycle)",
                  "deeper");
    }
    if (++converted_ > limits_.max_values) {
      FailConvert("pickle", "at most " + std::to_string(limits_.max_values) + " values",
                  "more (shared references expand)");
    }
  }

  std::string AttrName(int key) { return IsText(key) ? TextOf(key) : std::string(); }
  int Attr(int obj, const char* name) {
    for (const auto& [k, v] : N(obj).entries) {
      if (AttrName(k) == name) return v;
    }
    FailConvert(N(obj).global_name, std::string("attribute '") + name + "'", "missing");
  }

  std::shared_ptr<const NdArray> ArrayOf(int id, int depth, const std::string& what) {
    const PickleValue v = Convert(id, depth);
    if (v.kind == PickleValue::Kind::kArray) return v.array;
    if (v.is_number()) {
      const double x = v.number();
      return std::make_shared<NdArray>(NdArray::FromDoubles({}, &x));
    }
    FailConvert(what, "an array", v.Describe());
  }

  std::shared_ptr<const NdArray> Select(int obj, int depth) {
    const std::string& cls = N(obj).global_name;
    const auto a = ArrayOf(Attr(obj, "a"), depth + 1, cls + ".a");
    const auto idx_array = ArrayOf(Attr(obj, "idxs"), depth + 1, cls + ".idxs");
    std::vector<int64_t> idxs;
    try {
      idxs = idx_array->ToInt64s();
    } catch (const Error& e) {
      FailConvert(cls + ".idxs", "integer indices", e.what());
    }
    std::vector<int64_t> shape = {static_cast<int64_t>(idxs.size())};
    for (const auto& [k, v] : N(obj).entries) {
      if (AttrName(k) == "preferred_shape" && N(v).kind != NodeKind::kNone) {
        shape = IntsOf(v, "preferred_shape");
      }
    }
    int64_t count = 1;
    for (int64_t d : shape) {
      if (d < 0 || (d > 0 && count > (int64_t{1} << 40) / d)) {
        FailConvert(cls + ".preferred_shape", "a valid shape", "out of range");
      }
      count *= d;
    }
    if (count != static_cast<int64_t>(idxs.size())) {
      FailConvert(cls + ".preferred_shape",
                  std::to_string(idxs.size()) + " elements like idxs",
                  std::to_string(count));
    }
    auto out = std::make_shared<NdArray>();
    out->dtype = a->dtype;
    out->itemsize = a->itemsize;
    out->shape = shape;
    out->data.resize(idxs.size() * a->itemsize);
    const int64_t n = a->size();
    for (size_t i = 0; i < idxs.size(); ++i) {
      if (idxs[i] < 0 || idxs[i] >= n) {
        FailConvert(cls + ".idxs", "indices below " + std::to_string(n),
                    std::to_string(idxs[i]));
      }
      std::memcpy(out->data.data() + i * a->itemsize,
                  a->data.data() + idxs[i] * a->itemsize, a->itemsize);
    }
    return out;
  }

  std::shared_ptr<const SparseArrays> Sparse(int obj, int depth) {
    const std::string& cls = N(obj).global_name;
    auto s = std::make_shared<SparseArrays>();
    s->format = N(obj).global == Global::kCscMatrix ? "csc" : "csr";
    s->data = *ArrayOf(Attr(obj, "data"), depth + 1, cls + ".data");
    s->indices = *ArrayOf(Attr(obj, "indices"), depth + 1, cls + ".indices");
    s->indptr = *ArrayOf(Attr(obj, "indptr"), depth + 1, cls + ".indptr");
    int shape_id = -1;
    for (const auto& [k, v] : N(obj).entries) {
      const std::string name = AttrName(k);
      if (name == "_shape" || name == "shape") shape_id = v;
    }
    if (shape_id < 0) FailConvert(cls, "attribute '_shape'", "missing");
    const std::vector<int64_t> shape = IntsOf(shape_id, "sparse shape");
    if (shape.size() != 2 || shape[0] < 0 || shape[1] < 0) {
      FailConvert(cls + "._shape", "two non-negative dimensions", "other");
    }
    s->rows = shape[0];
    s->cols = shape[1];
    const int64_t outer = s->format == "csc" ? s->cols : s->rows;
    const int64_t inner = s->format == "csc" ? s->rows : s->cols;
    std::vector<int64_t> indptr, indices;
    try {
      indptr = s->indptr.ToInt64s();
      indices = s->indices.ToInt64s();
    } catch (const Error& e) {
      FailConvert(cls, "integer index arrays", e.what());
    }
    const int64_t nnz = s->data.size();
    if (static_cast<int64_t>(indptr.size()) != outer + 1 || indptr.front() != 0 ||
        indptr.back() != nnz || static_cast<int64_t>(indices.size()) != nnz) {
      FailConvert(cls,
                  "indptr of " + std::to_string(outer + 1) +
                      " entries from 0 to nnz and one index per value",
                  "inconsistent arrays");
    }
    for (size_t k = 1; k < indptr.size(); ++k) {
      if (indptr[k] < indptr[k - 1])
        FailConvert(cls + ".indptr", "non-decreasing", "not");
    }
    for (int64_t i : indices) {
      if (i < 0 || i >= inner) {
        FailConvert(cls + ".indices", "values below " + std::to_string(inner),
                    std::to_string(i));
      }
    }
    return s;
  }

  PickleValue Convert(int id, int depth) {
    Budget(depth);
    const Node& n = N(id);
    switch (n.kind) {
      case NodeKind::kList:
      case NodeKind::kTuple:
      case NodeKind::kSet:
        return Sequence(n, depth);
      case NodeKind::kDict:
        return Dict(n, depth);
      case NodeKind::kObject:
        return Object(id, n, depth);
      default:
        return Leaf(id, n);
    }
  }

 private:
  // A node without children: scalars, text, arrays, tensors and what is not plain data.
  PickleValue Leaf(int id, const Node& n) const {
    using K = PickleValue::Kind;
    PickleValue v;
    switch (n.kind) {
      case NodeKind::kNone:
        return Value(K::kNone, "NoneType");
      case NodeKind::kBool:
        v = Value(K::kBool, "bool");
        v.boolean = n.boolean;
        return v;
      case NodeKind::kInt:
        v = Value(K::kInt, "int");
        v.integer = n.integer;
        return v;
      case NodeKind::kFloat:
        v = Value(K::kFloat, "float");
        v.real = n.real;
        return v;
      case NodeKind::kText:
      case NodeKind::kPy2Str:
        v = Value(K::kText, "str");
        v.text = n.kind == NodeKind::kPy2Str ? Latin1ToUtf8(n.text) : n.text;
        return v;
      case NodeKind::kBytes:
        v = Value(K::kBytes, "bytes");
        v.text = n.text;
        return v;
      case NodeKind::kArray:
        v = Value(K::kArray, "numpy.ndarray");
        v.array = n.array;
        return v;
      case NodeKind::kTensor:
        v = Value(K::kTensor, "torch.Tensor");
        v.tensor = n.tensor;
        return v;
      case NodeKind::kPendingArray:
        v = Value(K::kUnsupported, "numpy.ndarray");
        v.text = "no state";
        return v;
      case NodeKind::kUnsupported:
        v = Value(K::kUnsupported, n.global_name);
        v.text = n.text;
        return v;
      default:  // globals, dtypes, storages
        v = Value(K::kUnsupported, KindName(id));
        v.text = "not plain data";
        return v;
    }
  }

  static PickleValue Value(PickleValue::Kind kind, const std::string& type_name) {
    PickleValue v;
    v.kind = kind;
    v.type_name = type_name;
    return v;
  }

  // list, tuple or set (a numpy object array of one item is that item).
  PickleValue Sequence(const Node& n, int depth) {
    if (n.global_name == "numpy object array" && n.integer == 0 && n.items.size() == 1) {
      return Convert(n.items[0], depth + 1);
    }
    PickleValue v = Value(PickleValue::Kind::kList, n.kind == NodeKind::kList    ? "list"
                                                    : n.kind == NodeKind::kTuple ? "tuple"
                                                                                 : "set");
    const std::vector<int> items = n.items;  // nodes_ is stable, but be explicit
    for (int item : items) v.items.push_back(Convert(item, depth + 1));
    return v;
  }

  PickleValue Dict(const Node& n, int depth) {
    PickleValue v = Value(PickleValue::Kind::kDict, "dict");
    const auto entries = n.entries;
    for (const auto& [key, value] : entries) {
      v.entries.emplace_back(Convert(key, depth + 1), Convert(value, depth + 1));
    }
    return v;
  }

  // chumpy arrays (Ch, Select) become arrays; scipy sparse matrices stay sparse.
  PickleValue Object(int id, const Node& n, int depth) {
    using K = PickleValue::Kind;
    if (n.global == Global::kCh) {
      PickleValue v = Value(K::kArray, n.global_name);
      v.array = ArrayOf(Attr(id, "x"), depth + 1, n.global_name + ".x");
      return v;
    }
    if (n.global == Global::kSelect) {
      PickleValue v = Value(K::kArray, n.global_name);
      v.array = Select(id, depth);
      return v;
    }
    PickleValue v = Value(K::kSparse, n.global_name);
    v.sparse = Sparse(id, depth);
    return v;
  }

  [[noreturn]] void FailConvert(const std::string& where, const std::string& expected,
                                const std::string& got) const {
    throw InputError(source_, where, expected, got);
  }
  const Node& N(int id) const { return nodes_[id]; }
  std::string KindName(int id) const { return DescribeNode(nodes_[id]); }
  bool IsText(int id) const {
    return N(id).kind == NodeKind::kText || N(id).kind == NodeKind::kPy2Str;
  }
  std::string TextOf(int id) const {
    return N(id).kind == NodeKind::kPy2Str ? Latin1ToUtf8(N(id).text) : N(id).text;
  }
  std::vector<int64_t> IntsOf(int id, const std::string& what) const {
    const Node& n = N(id);
    if (n.kind != NodeKind::kTuple && n.kind != NodeKind::kList) {
      FailConvert(what, "a tuple of integers", KindName(id));
    }
    std::vector<int64_t> v;
    for (int item : n.items) {
      if (N(item).kind == NodeKind::kInt) {
        v.push_back(N(item).integer);
      } else if (N(item).kind == NodeKind::kBool) {
        v.push_back(N(item).boolean);
      } else {
        FailConvert(what, "a tuple of integers", "a tuple with " + KindName(item));
      }
    }
    return v;
  }

  const std::vector<Node>& nodes_;
  const std::string& source_;
  const PickleLimits& limits_;
  int64_t converted_ = 0;
};

}  // namespace

PickleValue ConvertPickleGraph(const std::vector<Node>& nodes, int root,
                               const std::string& source, const PickleLimits& limits) {
  return Converter(nodes, source, limits).Convert(root, 0);
}

}  // namespace handlabel::pickle
