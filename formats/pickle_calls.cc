// Globals and the calls the reader understands (REDUCE, NEWOBJ, BUILD): numpy arrays,
// dtypes and scalars, bytes, sets, OrderedDict, chumpy/scipy instances and torch tensors.
#include "core/errors.h"
#include "formats/npy.h"
#include "formats/pickle_machine.h"
#include "formats/utf8.h"

namespace handlabel::pickle {

int PickleMachine::MakeGlobal(const std::string& module, const std::string& name) {
  Global global;
  DType storage_dtype;
  if (!LookupPickleGlobal(module, name, &global, &storage_dtype)) {
    Fail(
        "only the numpy, chumpy, scipy.sparse, collections and torch globals that "
        "model files use",
        "global '" + module + "." + name + "'");
  }
  const int id = NewNode(NodeKind::kGlobal);
  N(id).global = global;
  N(id).global_name = module + "." + name;
  N(id).dtype = storage_dtype;
  return id;
}

// A dtype from numpy.dtype(descr, align, copy); byte order comes with BUILD.
int PickleMachine::MakeDType(const std::vector<int>& args) {
  if (args.empty() || !IsText(args[0])) Fail("numpy.dtype(str, ...)", "other arguments");
  const std::string descr = TextOf(args[0], "dtype");
  const int id = NewNode(NodeKind::kDType);
  Node& d = N(id);
  d.text = descr;
  d.dtype_supported = ParseDTypeDescr(descr, &d.dtype, &d.itemsize, &d.big_endian);
  // numpy pickles "=" order as "<" on little-endian hosts; BUILD corrects it.
  return id;
}

void PickleMachine::BuildDType(int id, int state) {
  const std::vector<int>& s = TupleOf(state, "dtype state");
  if (s.size() < 2) Fail("a dtype state tuple", "a short tuple");
  const std::string order = TextOf(s[1], "dtype byte order");
  Node& d = N(id);
  if (order == ">") d.big_endian = true;
  if (order == "<") d.big_endian = false;
  if (s.size() >= 4 && N(s[3]).kind != NodeKind::kNone) {
    d.dtype_supported = false;  // structured dtype (names)
  }
  // Flexible dtypes carry their element size in the state (index 5).
  if (d.dtype_supported && !IsNumeric(d.dtype) && s.size() >= 6) {
    const int64_t elsize = IntOf(s[5], "dtype elsize");
    if (elsize > 0) d.itemsize = elsize;
  }
}

// Builds an NdArray from raw bytes in the given dtype; big-endian / Fortran data is
// converted to native C order.
std::shared_ptr<NdArray> PickleMachine::ArrayFromBytes(const std::vector<int64_t>& shape,
                                                       int dtype_id, bool fortran,
                                                       const std::string& raw) {
  const Node& d = N(dtype_id);
  auto a = std::make_shared<NdArray>();
  a->dtype = d.dtype;
  a->itemsize = d.itemsize;
  a->shape = shape;
  int64_t n_bytes = 0;
  try {
    n_bytes = CheckedByteCount(shape, d.itemsize, limits_.max_total_bytes, "ndarray");
  } catch (const Error& e) {
    Fail("an array within the size limit", e.what());
  }
  if (static_cast<uint64_t>(n_bytes) != raw.size()) {
    Fail(std::to_string(n_bytes) + " data bytes for shape " + a->ShapeString() + " of " +
             DTypeName(d.dtype),
         std::to_string(raw.size()) + " bytes");
  }
  ChargeBytes(raw.size());
  a->data.assign(raw.begin(), raw.end());
  ToNativeCOrder(d.big_endian, fortran, a.get());
  return a;
}

void PickleMachine::BuildArray(int id, int state) {
  std::vector<int> s = TupleOf(state, "ndarray state");
  if (s.size() == 5) s.erase(s.begin());  // (version, shape, dtype, fortran, data)
  if (s.size() != 4) Fail("an ndarray state of 4 or 5 items", KindName(state));
  if (N(s[1]).kind != NodeKind::kDType) Fail("a numpy dtype", KindName(s[1]));
  const std::vector<int64_t> shape = IntsOf(s[0], "ndarray shape");
  const bool fortran = IntOf(s[2], "ndarray fortran flag") != 0;
  const Node& d = N(s[1]);
  const NodeKind raw_kind = N(s[3]).kind;
  if (!d.text.empty() && d.text[0] == 'O' &&
      (raw_kind == NodeKind::kList || raw_kind == NodeKind::kTuple)) {
    // Object array (np.save of a sparse matrix, ...): its elements are pickled
    // objects, kept as a list; a 0-d one converts to its single element.
    const std::vector<int> items = N(s[3]).items;
    N(id).kind = NodeKind::kList;
    N(id).global_name = "numpy object array";
    N(id).integer = static_cast<int64_t>(shape.size());
    N(id).items = items;
    for (int item : items) Nest(id, item);
    return;
  }
  if (!d.dtype_supported) {
    N(id).kind = NodeKind::kUnsupported;
    N(id).global_name = "numpy.ndarray";
    N(id).text = "dtype '" + d.text + "'";
    return;
  }
  if (raw_kind != NodeKind::kBytes && raw_kind != NodeKind::kPy2Str &&
      raw_kind != NodeKind::kText) {
    Fail("the array's raw bytes", KindName(s[3]));
  }
  const std::string raw = LatinBytesOf(s[3], "array bytes");
  N(id).array = ArrayFromBytes(shape, s[1], fortran, raw);
  N(id).kind = NodeKind::kArray;
}

// A value of an unsupported dtype, kept so that converting it names the dtype.
int PickleMachine::UnsupportedDType(const char* what, int dtype_id) {
  const std::string descr = N(dtype_id).text;
  const int id = NewNode(NodeKind::kUnsupported);
  N(id).global_name = what;
  N(id).text = "dtype '" + descr + "'";
  return id;
}

int PickleMachine::NewInstance(int cls_id) {
  const Node cls = N(cls_id);  // a copy: NewNode may move every node
  if (cls.kind != NodeKind::kGlobal || !IsInstanceClass(cls.global)) {
    Fail(
        "a class the reader can build (chumpy Ch/Select, scipy csc/csr_matrix, "
        "OrderedDict)",
        KindName(cls_id));
  }
  if (cls.global == Global::kOrderedDict) return NewNode(NodeKind::kDict);
  const int id = NewNode(NodeKind::kObject);
  N(id).global = cls.global;
  N(id).global_name = cls.global_name;
  return id;
}

int PickleMachine::Reduce(int callable, int args_id) {
  const Node f = N(callable);  // a copy: NewNode below may move every node
  if (f.kind != NodeKind::kGlobal) Fail("a global to call", KindName(callable));
  const std::vector<int> args = TupleOf(args_id, "call arguments");
  switch (f.global) {
    case Global::kReconstruct:
      return ReduceArray(args);
    case Global::kDTypeClass:
      return MakeDType(args);
    case Global::kScalar:
      return ReduceScalar(args);
    case Global::kFromBuffer:
      return ReduceFromBuffer(args);
    case Global::kSet:
    case Global::kFrozenSet:
      if (args.empty()) return NewNode(NodeKind::kSet);
      if (args.size() != 1) Fail("set(iterable)", "other arguments");
      return MakeSequence(NodeKind::kSet, TupleOf(args[0], "set items"));
    case Global::kBytesClass:
    case Global::kBytearray:
      return ReduceBytes(args);
    case Global::kCodecsEncode:
      return ReduceCodecsEncode(args);
    case Global::kCopyregReconstructor:
      if (args.size() != 3 || N(args[1]).kind != NodeKind::kGlobal ||
          N(args[1]).global != Global::kObjectClass) {
        Fail("copy_reg._reconstructor(cls, object, None)", "other arguments");
      }
      return NewInstance(args[0]);
    case Global::kOrderedDict:
      if (!args.empty()) Fail("OrderedDict()", "arguments");
      return NewNode(NodeKind::kDict);
    case Global::kCh:
    case Global::kSelect:
    case Global::kCscMatrix:
    case Global::kCsrMatrix:
      return NewInstance(callable);
    case Global::kRebuildTensorV2:
      return ReduceRebuildTensor(args);
    case Global::kLoadFromBytes: {
      if (args.size() != 1) Fail("_load_from_bytes(bytes)", "other arguments");
      const std::string saved = BytesOf(args[0], "saved storage");  // a copy
      return LoadStorageFromBytes(saved);
    }
    case Global::kRebuildParameter:
      if (args.empty() ||
          (N(args[0]).kind != NodeKind::kTensor && N(args[0]).kind != NodeKind::kArray)) {
        Fail("_rebuild_parameter(tensor, ...)", "other arguments");
      }
      return args[0];
    case Global::kNdarray:
    case Global::kObjectClass:
    case Global::kStorage:
      break;
  }
  Fail("a callable global", "call of " + f.global_name);
}

// numpy.core.multiarray._reconstruct(numpy.ndarray, ...): the array comes with BUILD.
int PickleMachine::ReduceArray(const std::vector<int>& args) {
  if (args.empty() || N(args[0]).kind != NodeKind::kGlobal ||
      N(args[0]).global != Global::kNdarray) {
    Fail("_reconstruct(numpy.ndarray, ...)", "another class");
  }
  const int id = NewNode(NodeKind::kPendingArray);
  N(id).global_name = "numpy.ndarray";
  return id;
}

// numpy.core.multiarray.scalar(dtype, bytes): a Python float, bool or int.
int PickleMachine::ReduceScalar(const std::vector<int>& args) {
  if (args.size() != 2 || N(args[0]).kind != NodeKind::kDType) {
    Fail("scalar(dtype, bytes)", "other arguments");
  }
  if (!N(args[0]).dtype_supported || !IsNumeric(N(args[0]).dtype)) {
    return UnsupportedDType("numpy scalar", args[0]);
  }
  const auto a = ArrayFromBytes({}, args[0], false, LatinBytesOf(args[1], "scalar data"));
  const double v = a->ToDoubles()[0];
  switch (a->dtype) {
    case DType::kFloat16:
    case DType::kFloat32:
    case DType::kFloat64:
      return MakeFloat(v);
    case DType::kBool:
      return MakeBool(v != 0);
    default:
      return MakeInt(a->ToInt64s()[0]);
  }
}

// numpy _frombuffer(buffer, dtype, shape, order), numpy's protocol 5 arrays.
int PickleMachine::ReduceFromBuffer(const std::vector<int>& args) {
  if (args.size() != 4 || N(args[1]).kind != NodeKind::kDType) {
    Fail("_frombuffer(buffer, dtype, shape, order)", "other arguments");
  }
  if (!N(args[1]).dtype_supported) return UnsupportedDType("numpy.ndarray", args[1]);
  const bool fortran = TextOf(args[3], "order") == "F";
  auto array = ArrayFromBytes(IntsOf(args[2], "shape"), args[1], fortran,
                              BytesOf(args[0], "buffer"));
  const int id = NewNode(NodeKind::kArray);
  N(id).array = std::move(array);
  return id;
}

int PickleMachine::ReduceBytes(const std::vector<int>& args) {
  if (args.empty()) return MakeString(NodeKind::kBytes, "");
  const NodeKind k = N(args[0]).kind;
  if (k == NodeKind::kBytes || k == NodeKind::kPy2Str) {
    return MakeString(NodeKind::kBytes, N(args[0]).text);
  }
  std::string raw;  // Python 3 protocol 2: bytearray(str, 'latin-1')
  if (k == NodeKind::kText && Utf8ToLatin1(N(args[0]).text, &raw)) {
    return MakeString(NodeKind::kBytes, raw);
  }
  Fail("bytes() or bytearray(bytes)", "other arguments");
}

// _codecs.encode(str, 'latin1'): how protocol 2 pickles Python 3 bytes.
int PickleMachine::ReduceCodecsEncode(const std::vector<int>& args) {
  if (args.size() != 2 || N(args[0]).kind != NodeKind::kText) {
    Fail("_codecs.encode(str, 'latin1')", "other arguments");
  }
  const std::string codec = TextOf(args[1], "codec");
  if (codec != "latin1" && codec != "latin-1" && codec != "iso-8859-1") {
    Fail("the latin1 codec", "'" + codec + "'");
  }
  std::string raw;
  if (!Utf8ToLatin1(N(args[0]).text, &raw)) Fail("Latin-1 text", "other text");
  return MakeString(NodeKind::kBytes, raw);
}

// torch._utils._rebuild_tensor_v2(storage, offset, size, stride, requires_grad,
// hooks[, metadata]).
int PickleMachine::ReduceRebuildTensor(const std::vector<int>& args) {
  if (args.size() < 4 || N(args[0]).kind != NodeKind::kStorage) {
    Fail("_rebuild_tensor_v2(storage, offset, size, stride, ...)", "other arguments");
  }
  auto t = std::make_shared<TensorRef>(*N(args[0]).tensor);
  t->storage_offset = IntOf(args[1], "storage offset");
  t->shape = IntsOf(args[2], "tensor size");
  t->stride = IntsOf(args[3], "tensor stride");
  if (t->shape.size() != t->stride.size()) {
    Fail("as many strides as dimensions", "a mismatch");
  }
  const std::shared_ptr<NdArray> storage = N(args[0]).array;
  if (storage) {  // the storage came with the pickle: the tensor is plain data
    auto array = TensorFromStorage(*t, *storage);
    const int id = NewNode(NodeKind::kArray);
    N(id).array = std::move(array);
    N(id).global_name = "torch.Tensor";
    return id;
  }
  const int id = NewNode(NodeKind::kTensor);
  N(id).tensor = t;
  return id;
}

void PickleMachine::Build(int obj, int state) {
  switch (N(obj).kind) {
    case NodeKind::kPendingArray:
      BuildArray(obj, state);
      return;
    case NodeKind::kDType:
      BuildDType(obj, state);
      return;
    case NodeKind::kObject:
    case NodeKind::kDict:
      BuildAttributes(obj, state);
      return;
    default:
      Fail("an object that takes BUILD state", KindName(obj));
  }
}

// State is a dict, or (dict, slots dict) from classes with __slots__.
void PickleMachine::BuildAttributes(int obj, int state) {
  std::vector<int> dicts;
  if (N(state).kind == NodeKind::kDict) {
    dicts.push_back(state);
  } else if (N(state).kind == NodeKind::kTuple && N(state).items.size() == 2) {
    for (int part : N(state).items) {
      if (N(part).kind == NodeKind::kDict) dicts.push_back(part);
    }
  } else {
    Fail("an attribute dict as object state", KindName(state));
  }
  if (N(obj).kind == NodeKind::kDict) return;  // OrderedDict attributes (_metadata)
  for (int d : dicts) {
    for (const auto& kv : N(d).entries) {
      N(obj).entries.push_back(kv);
      Nest(obj, kv.second);
    }
  }
}

}  // namespace handlabel::pickle
