#include "core/pickle_reader.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "core/errors.h"
#include "core/npy.h"
#include "core/pickle_globals.h"
#include "core/pickle_graph.h"
#include "core/utf8.h"
#include "core/zip_reader.h"

namespace handlabel {
namespace {

using pickle::ConvertPickleGraph;
using pickle::DescribeNode;
using pickle::Global;
using pickle::IsInstanceClass;
using pickle::LookupPickleGlobal;
using pickle::Node;
using pickle::NodeKind;
using pickle::PickleOpcodeName;

class Reader {
 public:
  // Reads the pickle that starts at byte `start` of `bytes` (torch's legacy format
  // holds several pickles one after another).
  Reader(const std::string& bytes, const std::string& source, const PickleLimits& limits,
         size_t start = 0)
      : in_(bytes), source_(source), limits_(limits), pos_(start) {}

  PickleValue Run() {
    const int root = Execute();
    return ConvertPickleGraph(nodes_, root, source_, limits_);
  }
  // Runs the opcodes up to STOP and returns the root node unconverted (a torch
  // storage stays a storage); end() is then the offset after STOP.
  Node RunToNode() { return nodes_[Execute()]; }
  size_t end() const { return pos_; }

 private:
  // ---- errors --------------------------------------------------------------------
  [[noreturn]] void Fail(const std::string& expected, const std::string& got) const {
    throw InputError(
        source_, "pickle", expected,
        got + " (opcode " + OpName() + " at offset " + std::to_string(op_offset_) + ")");
  }
  std::string OpName() const {
    const char* name = PickleOpcodeName(op_);
    if (name) return name;
    char hex[8];
    std::snprintf(hex, sizeof(hex), "0x%02x", op_);
    return hex;
  }
  [[noreturn]] void FailConvert(const std::string& where, const std::string& expected,
                                const std::string& got) const {
    throw InputError(source_, where, expected, got);
  }

  // ---- input ---------------------------------------------------------------------
  size_t Remaining() const { return in_.size() - pos_; }
  void Need(uint64_t n) const {
    if (n > Remaining()) {
      Fail(std::to_string(n) + " more bytes",
           "only " + std::to_string(Remaining()) + " left (truncated pickle)");
    }
  }
  uint64_t ReadLE(int bytes) {
    Need(bytes);
    uint64_t v = 0;
    for (int k = bytes - 1; k >= 0; --k)
      v = (v << 8) | static_cast<uint8_t>(in_[pos_ + k]);
    pos_ += bytes;
    return v;
  }
  std::string ReadBytes(uint64_t n) {
    Need(n);
    ChargeBytes(n);
    std::string s = in_.substr(pos_, static_cast<size_t>(n));
    pos_ += static_cast<size_t>(n);
    return s;
  }
  std::string ReadLine() {
    const size_t end = in_.find('\n', pos_);
    if (end == std::string::npos) Fail("a newline-terminated argument", "end of data");
    std::string s = in_.substr(pos_, end - pos_);
    pos_ = end + 1;
    return s;
  }
  void ChargeBytes(uint64_t n) {
    total_bytes_ += static_cast<int64_t>(n);
    if (total_bytes_ > limits_.max_total_bytes) {
      Fail("at most " + std::to_string(limits_.max_total_bytes) + " bytes of data",
           "more");
    }
  }

  // ---- nodes and stack -----------------------------------------------------------
  int NewNode(NodeKind kind) {
    if (static_cast<int64_t>(nodes_.size()) >= limits_.max_values) {
      Fail("at most " + std::to_string(limits_.max_values) + " values", "more");
    }
    nodes_.emplace_back();
    nodes_.back().kind = kind;
    return static_cast<int>(nodes_.size()) - 1;
  }
  // References into nodes_ are invalidated by NewNode: never hold one across it.
  Node& N(int id) { return nodes_[id]; }
  void Push(int id) { stack_.push_back(id); }
  int Pop() {
    if (stack_.size() <= MarkBase()) Fail("a value on the stack", "an empty stack");
    const int id = stack_.back();
    stack_.pop_back();
    return id;
  }
  int Top() {
    if (stack_.size() <= MarkBase()) Fail("a value on the stack", "an empty stack");
    return stack_.back();
  }
  size_t MarkBase() const { return marks_.empty() ? 0 : marks_.back(); }
  std::vector<int> PopMark() {
    if (marks_.empty()) Fail("a MARK before this opcode", "none");
    const size_t base = marks_.back();
    marks_.pop_back();
    std::vector<int> items(stack_.begin() + base, stack_.end());
    stack_.resize(base);
    return items;
  }
  // Records that `child` now sits inside `parent`, enforcing the nesting limit.
  void Nest(int parent, int child) {
    const int depth = N(child).depth + 1;
    if (depth > N(parent).depth) N(parent).depth = depth;
    if (N(parent).depth > limits_.max_depth) {
      Fail("nesting at most " + std::to_string(limits_.max_depth) + " levels deep",
           "deeper nesting");
    }
  }
  int MakeInt(int64_t v) {
    const int id = NewNode(NodeKind::kInt);
    N(id).integer = v;
    return id;
  }
  int MakeString(NodeKind kind, std::string s) {
    const int id = NewNode(kind);
    N(id).text = std::move(s);
    return id;
  }
  int MakeSequence(NodeKind kind, std::vector<int> items) {  // a copy (see N())
    const int id = NewNode(kind);
    for (int item : items) Nest(id, item);
    N(id).items = items;
    return id;
  }

  // ---- accessors used by the understood callables --------------------------------
  bool IsText(int id) {
    const NodeKind k = N(id).kind;
    return k == NodeKind::kText || k == NodeKind::kPy2Str;
  }
  std::string TextOf(int id, const char* what) {
    if (N(id).kind == NodeKind::kText) return N(id).text;
    if (N(id).kind == NodeKind::kPy2Str) return Latin1ToUtf8(N(id).text);
    Fail(std::string(what) + " as a string", KindName(id));
  }
  // Raw bytes: Python 3 bytes, Python 2 str.
  const std::string& BytesOf(int id, const char* what) {
    const NodeKind k = N(id).kind;
    if (k == NodeKind::kBytes || k == NodeKind::kPy2Str) return N(id).text;
    Fail(std::string(what) + " as bytes", KindName(id));
  }
  int64_t IntOf(int id, const char* what) {
    if (N(id).kind == NodeKind::kInt) return N(id).integer;
    if (N(id).kind == NodeKind::kBool) return N(id).boolean;
    Fail(std::string(what) + " as an integer", KindName(id));
  }
  std::vector<int> TupleOf(int id, const char* what) {  // a copy (see N())
    const NodeKind k = N(id).kind;
    if (k == NodeKind::kTuple || k == NodeKind::kList) return N(id).items;
    Fail(std::string(what) + " as a tuple", KindName(id));
  }
  std::vector<int64_t> IntsOf(int id, const char* what) {
    std::vector<int64_t> v;
    for (int item : TupleOf(id, what)) v.push_back(IntOf(item, what));
    return v;
  }
  std::string KindName(int id) const { return DescribeNode(nodes_[id]); }

  // ---- globals -------------------------------------------------------------------
  int MakeGlobal(const std::string& module, const std::string& name) {
    Global global;
    DType storage_dtype;
    if (LookupPickleGlobal(module, name, &global, &storage_dtype)) {
      const int id = NewNode(NodeKind::kGlobal);
      N(id).global = global;
      N(id).global_name = module + "." + name;
      N(id).dtype = storage_dtype;
      return id;
    }
    Fail(
        "only the numpy, chumpy, scipy.sparse, collections and torch globals that "
        "model files use",
        "global '" + module + "." + name + "'");
  }

  // A dtype from numpy.dtype(descr, align, copy); byte order comes with BUILD.
  int MakeDType(const std::vector<int>& args) {
    if (args.empty() || !IsText(args[0]))
      Fail("numpy.dtype(str, ...)", "other arguments");
    const std::string descr = TextOf(args[0], "dtype");
    const int id = NewNode(NodeKind::kDType);
    Node& d = N(id);
    d.text = descr;
    d.dtype_supported = ParseDTypeDescr(descr, &d.dtype, &d.itemsize, &d.big_endian);
    // numpy pickles "=" order as "<" on little-endian hosts; BUILD corrects it.
    return id;
  }

  void BuildDType(int id, int state) {
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
  std::shared_ptr<NdArray> ArrayFromBytes(const std::vector<int64_t>& shape, int dtype_id,
                                          bool fortran, const std::string& raw) {
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
      Fail(std::to_string(n_bytes) + " data bytes for shape " + a->ShapeString() +
               " of " + DTypeName(d.dtype),
           std::to_string(raw.size()) + " bytes");
    }
    ChargeBytes(raw.size());
    a->data.assign(raw.begin(), raw.end());
    ToNativeCOrder(d.big_endian, fortran, a.get());
    return a;
  }

  void BuildArray(int id, int state) {
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
    std::string raw = N(s[3]).text;
    // Python 3 pickles of Python 2 buffers arrive as str when loaded with latin1.
    if (raw_kind == NodeKind::kText && !Utf8ToLatin1(N(s[3]).text, &raw)) {
      Fail("array bytes", "non-Latin-1 text");
    }
    N(id).array = ArrayFromBytes(shape, s[1], fortran, raw);
    N(id).kind = NodeKind::kArray;
  }

  // ---- REDUCE / NEWOBJ / BUILD ---------------------------------------------------
  int NewInstance(int cls_id) {
    // Copies, not references: NewNode may move every node.
    const Node cls = N(cls_id);
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

  int Reduce(int callable, int args_id) {
    const Node f = N(callable);  // a copy: NewNode below may move every node
    if (f.kind != NodeKind::kGlobal) Fail("a global to call", KindName(callable));
    const std::vector<int> args = TupleOf(args_id, "call arguments");
    switch (f.global) {
      case Global::kReconstruct: {
        if (args.empty() || N(args[0]).kind != NodeKind::kGlobal ||
            N(args[0]).global != Global::kNdarray) {
          Fail("_reconstruct(numpy.ndarray, ...)", "another class");
        }
        const int id = NewNode(NodeKind::kPendingArray);
        N(id).global_name = "numpy.ndarray";
        return id;
      }
      case Global::kDTypeClass:
        return MakeDType(args);
      case Global::kScalar: {
        if (args.size() != 2 || N(args[0]).kind != NodeKind::kDType) {
          Fail("scalar(dtype, bytes)", "other arguments");
        }
        if (!N(args[0]).dtype_supported || !IsNumeric(N(args[0]).dtype)) {
          const int id = NewNode(NodeKind::kUnsupported);
          N(id).global_name = "numpy scalar";
          N(id).text = "dtype '" + N(args[0]).text + "'";
          return id;
        }
        std::string raw;
        if (N(args[1]).kind != NodeKind::kText) {
          raw = BytesOf(args[1], "scalar data");
        } else if (!Utf8ToLatin1(N(args[1]).text, &raw)) {
          Fail("scalar bytes", "non-Latin-1 text");
        }
        const auto a = ArrayFromBytes({}, args[0], false, raw);
        const double v = a->ToDoubles()[0];
        if (a->dtype == DType::kFloat16 || a->dtype == DType::kFloat32 ||
            a->dtype == DType::kFloat64) {
          const int id = NewNode(NodeKind::kFloat);
          N(id).real = v;
          return id;
        }
        if (a->dtype == DType::kBool) {
          const int id = NewNode(NodeKind::kBool);
          N(id).boolean = v != 0;
          return id;
        }
        return MakeInt(a->ToInt64s()[0]);
      }
      case Global::kFromBuffer: {
        // _frombuffer(buffer, dtype, shape, order)
        if (args.size() != 4 || N(args[1]).kind != NodeKind::kDType) {
          Fail("_frombuffer(buffer, dtype, shape, order)", "other arguments");
        }
        const int id = NewNode(NodeKind::kArray);
        if (!N(args[1]).dtype_supported) {
          N(id).kind = NodeKind::kUnsupported;
          N(id).global_name = "numpy.ndarray";
          N(id).text = "dtype '" + N(args[1]).text + "'";
          return id;
        }
        const bool fortran = TextOf(args[3], "order") == "F";
        N(id).array = ArrayFromBytes(IntsOf(args[2], "shape"), args[1], fortran,
                                     BytesOf(args[0], "buffer"));
        return id;
      }
      case Global::kSet:
      case Global::kFrozenSet: {
        if (args.empty()) return NewNode(NodeKind::kSet);
        if (args.size() != 1) Fail("set(iterable)", "other arguments");
        return MakeSequence(NodeKind::kSet, TupleOf(args[0], "set items"));
      }
      case Global::kBytesClass:
      case Global::kBytearray: {
        if (args.empty()) return MakeString(NodeKind::kBytes, "");
        if (N(args[0]).kind == NodeKind::kBytes || N(args[0]).kind == NodeKind::kPy2Str) {
          return MakeString(NodeKind::kBytes, N(args[0]).text);
        }
        std::string raw;  // Python 3 protocol 2: bytearray(str, 'latin-1')
        if (N(args[0]).kind == NodeKind::kText && Utf8ToLatin1(N(args[0]).text, &raw)) {
          return MakeString(NodeKind::kBytes, raw);
        }
        Fail("bytes() or bytearray(bytes)", "other arguments");
      }
      case Global::kCodecsEncode: {
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
      case Global::kCopyregReconstructor: {
        if (args.size() != 3 || N(args[1]).kind != NodeKind::kGlobal ||
            N(args[1]).global != Global::kObjectClass) {
          Fail("copy_reg._reconstructor(cls, object, None)", "other arguments");
        }
        return NewInstance(args[0]);
      }
      case Global::kOrderedDict:
        if (!args.empty()) Fail("OrderedDict()", "arguments");
        return NewNode(NodeKind::kDict);
      case Global::kCh:
      case Global::kSelect:
      case Global::kCscMatrix:
      case Global::kCsrMatrix:
        return NewInstance(callable);
      case Global::kRebuildTensorV2: {
        // (storage, storage_offset, size, stride, requires_grad, hooks[, metadata])
        if (args.size() < 4 || N(args[0]).kind != NodeKind::kStorage) {
          Fail("_rebuild_tensor_v2(storage, offset, size, stride, ...)",
               "other arguments");
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
          const int id = NewNode(NodeKind::kArray);
          N(id).array = TensorFromStorage(*t, *storage);
          N(id).global_name = "torch.Tensor";
          return id;
        }
        const int id = NewNode(NodeKind::kTensor);
        N(id).tensor = t;
        return id;
      }
      case Global::kLoadFromBytes: {
        if (args.size() != 1) Fail("_load_from_bytes(bytes)", "other arguments");
        const std::string saved = BytesOf(args[0], "saved storage");  // a copy
        return LoadStorageFromBytes(saved);
      }
      case Global::kRebuildParameter: {
        if (args.empty() || (N(args[0]).kind != NodeKind::kTensor &&
                             N(args[0]).kind != NodeKind::kArray)) {
          Fail("_rebuild_parameter(tensor, ...)", "other arguments");
        }
        return args[0];
      }
      case Global::kNdarray:
      case Global::kObjectClass:
      case Global::kStorage:
        break;
    }
    Fail("a callable global", "call of " + f.global_name);
  }

  void Build(int obj, int state) {
    Node& o = N(obj);
    switch (o.kind) {
      case NodeKind::kPendingArray:
        BuildArray(obj, state);
        return;
      case NodeKind::kDType:
        BuildDType(obj, state);
        return;
      case NodeKind::kObject:
      case NodeKind::kDict: {
        // State is a dict, or (dict, slots dict) from classes with __slots__.
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
        if (o.kind == NodeKind::kDict) return;  // OrderedDict attributes (_metadata)
        for (int d : dicts) {
          for (const auto& kv : N(d).entries) {
            N(obj).entries.push_back(kv);
            Nest(obj, kv.second);
          }
        }
        return;
      }
      default:
        Fail("an object that takes BUILD state", KindName(obj));
    }
  }

  int PersistentLoad(int pid) {
    // torch.save: ('storage', <Type>Storage, key, location, numel); the legacy
    // (pre-zip) format adds view_metadata, None for a whole storage.
    const std::vector<int>& t = TupleOf(pid, "persistent id");
    const bool legacy = t.size() == 6 && N(t[5]).kind == NodeKind::kNone;
    if ((t.size() != 5 && !legacy) || !IsText(t[0]) ||
        TextOf(t[0], "persistent id tag") != "storage" ||
        N(t[1]).kind != NodeKind::kGlobal || N(t[1]).global != Global::kStorage) {
      Fail(
          "a torch storage persistent id ('storage', torch.<Type>Storage, key, "
          "location, numel[, None])",
          "another persistent id");
    }
    auto ref = std::make_shared<TensorRef>();
    ref->dtype = N(t[1]).dtype;
    ref->storage_key = TextOf(t[2], "storage key");
    ref->device = TextOf(t[3], "storage location");
    ref->storage_numel = IntOf(t[4], "storage numel");
    if (ref->storage_numel < 0) Fail("a non-negative storage size", "a negative one");
    const int id = NewNode(NodeKind::kStorage);
    N(id).tensor = ref;
    return id;
  }

  // ---- torch storages saved inside the pickle (torch.storage._load_from_bytes) ----
  // Pickling a tensor with plain pickle (not torch.save) stores its storage as
  // _load_from_bytes(torch.save(storage)): the legacy torch.save format (magic number,
  // protocol 1001, sys_info, the storage's persistent id, its key list, then per key an
  // int64 element count and the raw little-endian elements) or the zip form
  // (<name>/data.pkl + <name>/data/<key>). Only a single whole storage is accepted;
  // every count is checked against the bytes present before anything is allocated.
  int LoadStorageFromBytes(const std::string& saved) {
    const std::string what = source_ + " (saved torch storage)";
    Node storage;
    std::string data;
    if (LooksLikeZip(saved)) {
      const ZipReader zip = ZipReader::FromBytes(saved, what);
      const ZipEntry* pkl = nullptr;
      for (const ZipEntry& e : zip.entries()) {
        const size_t n = e.name.size();
        if (n >= 8 && e.name.compare(n - 8, 8, "data.pkl") == 0 &&
            (n == 8 || e.name[n - 9] == '/'))
          pkl = &e;
      }
      if (!pkl) Fail("a torch.save archive with data.pkl", "none in the saved storage");
      const std::string pickled = zip.Read(*pkl);
      storage = Reader(pickled, what, limits_).RunToNode();
      RequireSavedStorage(storage);
      const std::string prefix = pkl->name.substr(0, pkl->name.size() - 8);
      const std::string entry = prefix + "data/" + storage.tensor->storage_key;
      if (!zip.Find(entry)) Fail("the storage entry " + entry, "none");
      data = zip.Read(entry);
    } else {
      size_t pos = SkipTorchMagic(saved);
      Reader version(saved, what, limits_, pos);
      const PickleValue protocol = version.Run();
      if (protocol.kind != PickleValue::Kind::kInt || protocol.integer != 1001) {
        Fail("torch legacy protocol version 1001", protocol.Describe());
      }
      Reader sys_info(saved, what, limits_, version.end());
      const PickleValue info = sys_info.Run();
      const PickleValue* little = info.Find("little_endian");
      if (little && little->kind == PickleValue::Kind::kBool && !little->boolean) {
        Fail("a storage saved on a little-endian machine", "big-endian");
      }
      Reader main(saved, what, limits_, sys_info.end());
      storage = main.RunToNode();
      RequireSavedStorage(storage);
      Reader keys(saved, what, limits_, main.end());
      const PickleValue key_list = keys.Run();
      if (key_list.kind != PickleValue::Kind::kList || key_list.items.size() != 1 ||
          key_list.items[0].kind != PickleValue::Kind::kText ||
          key_list.items[0].text != storage.tensor->storage_key) {
        Fail("the key list ['" + storage.tensor->storage_key + "']", key_list.Describe());
      }
      pos = keys.end();
      if (saved.size() - pos < 8) Fail("the storage's element count", "end of data");
      int64_t count = 0;
      for (int k = 7; k >= 0; --k)
        count = (count << 8) | static_cast<uint8_t>(saved[pos + k]);
      pos += 8;
      if (count != storage.tensor->storage_numel) {
        Fail(std::to_string(storage.tensor->storage_numel) + " stored elements",
             std::to_string(count));
      }
      data = saved.substr(pos);
    }
    const int64_t itemsize = FixedDTypeSize(storage.tensor->dtype);
    const int64_t numel = storage.tensor->storage_numel;
    if (numel > limits_.max_total_bytes / itemsize ||
        static_cast<int64_t>(data.size()) != numel * itemsize) {
      Fail(std::to_string(numel) + " elements of " + std::to_string(itemsize) +
               " bytes in the saved storage",
           std::to_string(data.size()) + " bytes");
    }
    ChargeBytes(data.size());
    auto array = std::make_shared<NdArray>();
    array->dtype = storage.tensor->dtype;
    array->itemsize = itemsize;
    array->shape = {numel};
    array->data.assign(data.begin(), data.end());
    const int id = NewNode(NodeKind::kStorage);
    N(id).tensor = storage.tensor;
    N(id).array = array;
    return id;
  }

  // The legacy format's first pickle: the magic number 0x1950a86a20f9469cfc6c (a
  // 10-byte LONG1). Returns the offset after it.
  size_t SkipTorchMagic(const std::string& saved) {
    static const unsigned char kMagic[] = {0x8a, 0x0a, 0x6c, 0xfc, 0x9c, 0x46, 0xf9,
                                           0x20, 0x6a, 0xa8, 0x50, 0x19, '.'};
    size_t pos = 0;
    if (saved.size() >= 2 && static_cast<uint8_t>(saved[0]) == 0x80) pos = 2;  // PROTO
    if (saved.size() < pos + sizeof(kMagic) ||
        std::memcmp(saved.data() + pos, kMagic, sizeof(kMagic)) != 0) {
      Fail("torch.save bytes (zip, or the legacy magic number)", "other bytes");
    }
    return pos + sizeof(kMagic);
  }

  void RequireSavedStorage(const Node& storage) {
    if (storage.kind != NodeKind::kStorage || !storage.tensor) {
      Fail("a saved torch storage", DescribeNode(storage));
    }
  }

  // The elements of a tensor view of an in-memory storage, in C order. Offsets and
  // strides are checked against the storage before anything is read.
  std::shared_ptr<NdArray> TensorFromStorage(const TensorRef& t, const NdArray& storage) {
    const int64_t stored = storage.shape[0];
    int64_t numel = 1, last = t.storage_offset;
    for (size_t d = 0; d < t.shape.size(); ++d) {
      if (t.shape[d] < 0 || t.stride[d] < 0) {
        Fail("non-negative tensor sizes and strides", "a negative one");
      }
      if (t.shape[d] == 0) {
        numel = 0;
        continue;
      }
      if (t.stride[d] > 0 && t.shape[d] - 1 > stored / t.stride[d]) {
        Fail("a tensor view inside its storage", "strides beyond it");
      }
      last += (t.shape[d] - 1) * t.stride[d];  // each term <= stored: no overflow
      if (numel > 0 && t.shape[d] > limits_.max_total_bytes / numel) {
        Fail("a tensor within the size limit", "a larger one");
      }
      numel *= t.shape[d];
    }
    if (numel > 0 &&
        (t.storage_offset < 0 || t.storage_offset > stored || last >= stored)) {
      Fail("a tensor view inside its storage of " + std::to_string(stored) + " elements",
           "element " + std::to_string(last));
    }
    auto a = std::make_shared<NdArray>();
    a->dtype = storage.dtype;
    a->itemsize = storage.itemsize;
    a->shape = t.shape;
    ChargeBytes(static_cast<uint64_t>(numel * a->itemsize));
    a->data.resize(static_cast<size_t>(numel * a->itemsize));
    std::vector<int64_t> index(t.shape.size(), 0);
    for (int64_t i = 0; i < numel; ++i) {
      int64_t at = t.storage_offset;
      for (size_t d = 0; d < index.size(); ++d) at += index[d] * t.stride[d];
      std::memcpy(a->data.data() + i * a->itemsize,
                  storage.data.data() + at * a->itemsize,
                  static_cast<size_t>(a->itemsize));
      for (size_t d = index.size(); d-- > 0;) {  // next index in C order
        if (++index[d] < t.shape[d]) break;
        index[d] = 0;
      }
    }
    return a;
  }

  // ---- protocol 0 text arguments -------------------------------------------------
  int64_t ParseDecimal(std::string s, const char* what) {
    if (!s.empty() && s.back() == 'L') s.pop_back();
    if (s.empty()) Fail(std::string(what) + " digits", "nothing");
    const bool negative = s[0] == '-';
    size_t i = negative || s[0] == '+' ? 1 : 0;
    if (i == s.size()) Fail(std::string(what) + " digits", "'" + s + "'");
    // The magnitude int64_t holds: 2^63 for a negative number, 2^63 - 1 otherwise.
    const uint64_t limit = (uint64_t{1} << 63) - (negative ? 0 : 1);
    uint64_t v = 0;
    for (; i < s.size(); ++i) {
      if (!std::isdigit(static_cast<unsigned char>(s[i]))) {
        Fail(std::string(what) + " digits", "'" + s.substr(0, 40) + "'");
      }
      const uint64_t digit = static_cast<uint64_t>(s[i] - '0');
      if (v > (limit - digit) / 10) {
        Fail("an integer that fits 64 bits", "'" + s.substr(0, 40) + "'");
      }
      v = v * 10 + digit;
    }
    if (!negative) return static_cast<int64_t>(v);
    // -2^63 has no positive int64_t to negate.
    return v == (uint64_t{1} << 63) ? std::numeric_limits<int64_t>::min()
                                    : -static_cast<int64_t>(v);
  }

  int HexDigit(char c) {
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    Fail("a hex digit", std::string("'") + c + "'");
  }

  // Python repr of a str: '...' or "..." with backslash escapes.
  std::string UnquoteString(const std::string& s) {
    if (s.size() < 2 || (s[0] != '\'' && s[0] != '"') || s.back() != s[0]) {
      Fail("a quoted string", "'" + s.substr(0, 40) + "'");
    }
    std::string out;
    for (size_t i = 1; i + 1 < s.size(); ++i) {
      if (s[i] != '\\') {
        out.push_back(s[i]);
        continue;
      }
      if (++i >= s.size() - 1) Fail("a complete escape", "a trailing backslash");
      const char c = s[i];
      switch (c) {
        case 'n':
          out.push_back('\n');
          break;
        case 't':
          out.push_back('\t');
          break;
        case 'r':
          out.push_back('\r');
          break;
        case '\\':
          out.push_back('\\');
          break;
        case '\'':
          out.push_back('\'');
          break;
        case '"':
          out.push_back('"');
          break;
        case 'x': {
          if (i + 2 >= s.size()) Fail("\\x and two hex digits", "end");
          out.push_back(static_cast<char>(16 * HexDigit(s[i + 1]) + HexDigit(s[i + 2])));
          i += 2;
          break;
        }
        default:
          if (c >= '0' && c <= '7') {
            int v = 0, k = 0;
            while (k < 3 && i < s.size() - 1 && s[i] >= '0' && s[i] <= '7') {
              v = v * 8 + (s[i++] - '0');
              ++k;
            }
            --i;
            out.push_back(static_cast<char>(v & 0xFF));
          } else {
            out.push_back('\\');
            out.push_back(c);
          }
      }
    }
    return out;
  }

  // raw-unicode-escape: \uXXXX and \UXXXXXXXX escapes, other bytes are Latin-1.
  std::string DecodeRawUnicode(const std::string& s) {
    std::string out;
    for (size_t i = 0; i < s.size(); ++i) {
      const size_t digits = s[i] == '\\' && i + 1 < s.size() ? (s[i + 1] == 'u'   ? 4
                                                                : s[i + 1] == 'U' ? 8
                                                                                  : 0)
                                                             : 0;
      if (digits && i + 2 + digits <= s.size()) {
        uint32_t cp = 0;
        for (size_t k = 0; k < digits; ++k) {
          const char h = s[i + 2 + k];
          if (!std::isxdigit(static_cast<unsigned char>(h))) Fail("hex digits", "other");
          cp = cp * 16 + static_cast<uint32_t>(HexDigit(h));
        }
        if (cp > 0x10FFFF) Fail("a Unicode code point", "a larger number");
        AppendUtf8(cp, &out);
        i += 1 + digits;
      } else {
        AppendUtf8(static_cast<unsigned char>(s[i]), &out);
      }
    }
    return out;
  }

  // ---- the opcode loop -----------------------------------------------------------
  int Execute() {
    while (true) {
      op_offset_ = pos_;
      if (pos_ >= in_.size()) {
        op_ = 0;
        Fail("a STOP opcode", "end of data (truncated pickle)");
      }
      op_ = static_cast<uint8_t>(in_[pos_++]);
      switch (op_) {
        case 0x80: {  // PROTO
          const uint64_t proto = ReadLE(1);
          if (proto > 5) Fail("pickle protocol 0-5", "protocol " + std::to_string(proto));
          break;
        }
        case 0x95:
          ReadLE(8);
          break;     // FRAME: only a read-ahead hint
        case '.': {  // STOP
          const int root = Pop();
          return root;
        }
        case '(':
          marks_.push_back(stack_.size());
          break;
        case '0':
          Pop();
          break;
        case '1':
          PopMark();
          break;
        case '2':
          Push(Top());
          break;
        case 'N':
          Push(NewNode(NodeKind::kNone));
          break;
        case 0x88:
        case 0x89: {
          const int id = NewNode(NodeKind::kBool);
          N(id).boolean = op_ == 0x88;
          Push(id);
          break;
        }
        case 'I': {
          const std::string line = ReadLine();
          if (line == "00" || line == "01") {
            const int id = NewNode(NodeKind::kBool);
            N(id).boolean = line == "01";
            Push(id);
          } else {
            Push(MakeInt(ParseDecimal(line, "INT")));
          }
          break;
        }
        case 'L':
          Push(MakeInt(ParseDecimal(ReadLine(), "LONG")));
          break;
        case 'J':
          Push(MakeInt(static_cast<int32_t>(ReadLE(4))));
          break;
        case 'K':
          Push(MakeInt(static_cast<int64_t>(ReadLE(1))));
          break;
        case 'M':
          Push(MakeInt(static_cast<int64_t>(ReadLE(2))));
          break;
        case 0x8a:
        case 0x8b: {  // LONG1 / LONG4: little-endian two's complement
          const uint64_t n = ReadLE(op_ == 0x8a ? 1 : 4);
          if (n > 8) Fail("an integer of at most 8 bytes", std::to_string(n) + " bytes");
          Need(n);
          uint64_t v = 0;
          for (uint64_t k = n; k-- > 0;)
            v = (v << 8) | static_cast<uint8_t>(in_[pos_ + k]);
          if (n > 0 && n < 8 && (static_cast<uint8_t>(in_[pos_ + n - 1]) & 0x80)) {
            v |= ~uint64_t{0} << (8 * n);  // sign-extend
          }
          pos_ += n;
          Push(MakeInt(static_cast<int64_t>(v)));
          break;
        }
        case 'F': {
          const std::string line = ReadLine();
          char* end = nullptr;
          const double v = std::strtod(line.c_str(), &end);
          if (line.empty() || *end != '\0')
            Fail("a float", "'" + line.substr(0, 40) + "'");
          const int id = NewNode(NodeKind::kFloat);
          N(id).real = v;
          Push(id);
          break;
        }
        case 'G': {
          uint64_t bits = 0;
          Need(8);
          for (int k = 0; k < 8; ++k)
            bits = (bits << 8) | static_cast<uint8_t>(in_[pos_ + k]);
          pos_ += 8;
          double v;
          std::memcpy(&v, &bits, 8);
          const int id = NewNode(NodeKind::kFloat);
          N(id).real = v;
          Push(id);
          break;
        }
        case 'S':
          Push(MakeString(NodeKind::kPy2Str, UnquoteString(ReadLine())));
          break;
        case 'T':
          Push(MakeString(NodeKind::kPy2Str, ReadBytes(ReadLE(4))));
          break;
        case 'U':
          Push(MakeString(NodeKind::kPy2Str, ReadBytes(ReadLE(1))));
          break;
        case 'V':
          Push(MakeString(NodeKind::kText, DecodeRawUnicode(ReadLine())));
          break;
        case 'X':
          Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(4))));
          break;
        case 0x8c:
          Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(1))));
          break;
        case 0x8d:
          Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(8))));
          break;
        case 'B':
          Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(4))));
          break;
        case 'C':
          Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(1))));
          break;
        case 0x8e:
        case 0x96:
          Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(8))));
          break;
        case 0x98:
          Top();
          break;  // READONLY_BUFFER: no effect on our values
        case ')':
          Push(NewNode(NodeKind::kTuple));
          break;
        case ']':
          Push(NewNode(NodeKind::kList));
          break;
        case '}':
          Push(NewNode(NodeKind::kDict));
          break;
        case 0x8f:
          Push(NewNode(NodeKind::kSet));
          break;
        case 't':
          Push(MakeSequence(NodeKind::kTuple, PopMark()));
          break;
        case 'l':
          Push(MakeSequence(NodeKind::kList, PopMark()));
          break;
        case 0x91:
          Push(MakeSequence(NodeKind::kSet, PopMark()));
          break;
        case 0x85:
        case 0x86:
        case 0x87: {
          const int n = op_ - 0x84;
          std::vector<int> items(n);
          for (int k = n - 1; k >= 0; --k) items[k] = Pop();
          Push(MakeSequence(NodeKind::kTuple, items));
          break;
        }
        case 'd': {
          const std::vector<int> items = PopMark();
          if (items.size() % 2) Fail("key-value pairs", "an odd number of items");
          const int id = NewNode(NodeKind::kDict);
          for (size_t k = 0; k < items.size(); k += 2)
            SetItem(id, items[k], items[k + 1]);
          Push(id);
          break;
        }
        case 'a': {
          const int item = Pop();
          Append(Top(), item);
          break;
        }
        case 'e':
        case 0x90: {
          const std::vector<int> items = PopMark();
          const int target = Top();
          for (int item : items) Append(target, item);
          break;
        }
        case 's': {
          const int value = Pop();
          const int key = Pop();
          SetItem(Top(), key, value);
          break;
        }
        case 'u': {
          const std::vector<int> items = PopMark();
          if (items.size() % 2) Fail("key-value pairs", "an odd number of items");
          const int target = Top();
          for (size_t k = 0; k < items.size(); k += 2)
            SetItem(target, items[k], items[k + 1]);
          break;
        }
        case 'g':
          Push(MemoGet(static_cast<uint64_t>(ParseDecimal(ReadLine(), "GET"))));
          break;
        case 'h':
          Push(MemoGet(ReadLE(1)));
          break;
        case 'j':
          Push(MemoGet(ReadLE(4)));
          break;
        case 'p':
          memo_[static_cast<uint64_t>(ParseDecimal(ReadLine(), "PUT"))] = Top();
          break;
        case 'q':
          memo_[ReadLE(1)] = Top();
          break;
        case 'r':
          memo_[ReadLE(4)] = Top();
          break;
        case 0x94:
          memo_[memo_.size()] = Top();
          break;
        case 'c': {
          const std::string module = ReadLine();
          const std::string name = ReadLine();
          Push(MakeGlobal(module, name));
          break;
        }
        case 0x93: {  // STACK_GLOBAL
          const int name = Pop();
          const int module = Pop();
          if (N(name).kind != NodeKind::kText || N(module).kind != NodeKind::kText) {
            Fail("module and name strings", "other values");
          }
          const std::string module_name = N(module).text, global_name = N(name).text;
          Push(MakeGlobal(module_name, global_name));
          break;
        }
        case 'R': {
          const int args = Pop();
          const int callable = Pop();
          Push(Reduce(callable, args));
          break;
        }
        case 0x81: {  // NEWOBJ
          const int args = Pop();
          const int cls = Pop();
          TupleOf(args, "NEWOBJ arguments");
          Push(NewInstance(cls));
          break;
        }
        case 0x92: {  // NEWOBJ_EX
          Pop();      // kwargs
          Pop();      // args
          Push(NewInstance(Pop()));
          break;
        }
        case 'i': {  // INST module\nname\n with MARKed args
          const std::string module = ReadLine();
          const std::string name = ReadLine();
          PopMark();
          Push(NewInstance(MakeGlobal(module, name)));
          break;
        }
        case 'o': {  // OBJ: MARK cls args...
          const std::vector<int> items = PopMark();
          if (items.empty()) Fail("a class after MARK", "nothing");
          Push(NewInstance(items[0]));
          break;
        }
        case 'b': {
          const int state = Pop();
          Build(Top(), state);
          break;
        }
        case 'Q':
          Push(PersistentLoad(Pop()));
          break;
        case 'P':
          Fail("torch storage persistent ids (BINPERSID)", "a text persistent id");
        case 0x82:
        case 0x83:
        case 0x84:
          Fail("no extension registry codes", "an EXT opcode");
        case 0x97:
          Fail("in-band data", "an out-of-band buffer");
        default:
          Fail("a pickle opcode", "unknown opcode");
      }
      if (marks_.size() > static_cast<size_t>(limits_.max_values)) {
        Fail("fewer MARKs", "too many");
      }
    }
  }

  int MemoGet(uint64_t key) {
    const auto it = memo_.find(key);
    if (it == memo_.end()) Fail("a stored memo entry", "memo key " + std::to_string(key));
    return it->second;
  }

  void Append(int target, int item) {
    const NodeKind k = N(target).kind;
    if (k != NodeKind::kList && k != NodeKind::kSet) {
      Fail("a list or set to append to", KindName(target));
    }
    Nest(target, item);
    N(target).items.push_back(item);
  }

  void SetItem(int target, int key, int value) {
    if (N(target).kind != NodeKind::kDict)
      Fail("a dict to set items on", KindName(target));
    Nest(target, key);
    Nest(target, value);
    N(target).entries.emplace_back(key, value);
  }

  const std::string& in_;
  const std::string& source_;
  const PickleLimits& limits_;
  size_t pos_ = 0;
  size_t op_offset_ = 0;
  uint8_t op_ = 0;
  std::vector<Node> nodes_;
  std::vector<int> stack_;
  std::vector<size_t> marks_;
  std::unordered_map<uint64_t, int> memo_;
  int64_t total_bytes_ = 0;
};

}  // namespace

bool PickleLimits::Check(std::string* error) const {
  if (max_values < 1 || max_depth < 1 || max_total_bytes < 0) {
    *error = "PickleLimits: max_values and max_depth must be positive";
    return false;
  }
  return true;
}

PickleValue ReadPickle(const std::string& bytes, const std::string& source,
                       const PickleLimits& limits) {
  std::string error;
  if (!limits.Check(&error)) throw InputError(source, "PickleLimits", error);
  return Reader(bytes, source, limits).Run();
}

PickleValue ReadPickleFile(const std::string& path, const PickleLimits& limits) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "a readable pickle file", "cannot open");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return ReadPickle(buffer.str(), path, limits);
}

}  // namespace handlabel
