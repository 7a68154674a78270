#pragma once
// Internal to the restricted pickle reader (pickle_reader.h): the opcode machine that
// builds the object graph of pickle_graph.h. Its members are defined by role:
//   pickle_reader.cc         input, stack, memo and the opcode loop
//   pickle_opcodes.cc        the opcodes, one group per function
//   pickle_calls.cc          REDUCE / NEWOBJ / BUILD of the understood globals
//   pickle_torch_storage.cc  torch storages (persistent ids, _load_from_bytes)
//   pickle_text.cc           protocol 0's text arguments

#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include "formats/pickle_graph.h"

namespace handlabel::pickle {

class PickleMachine {
 public:
  // Reads the pickle that starts at byte `start` of `bytes` (torch's legacy format
  // holds several pickles one after another).
  PickleMachine(const std::string& bytes, const std::string& source,
                const PickleLimits& limits, size_t start = 0)
      : in_(bytes), source_(source), limits_(limits), pos_(start) {}

  PickleValue Run();
  // Runs the opcodes up to STOP and returns the root node unconverted (a torch
  // storage stays a storage); end() is then the offset after STOP.
  Node RunToNode() { return nodes_[Execute()]; }
  size_t end() const { return pos_; }

 private:
  // Errors name the source, the opcode and its offset.
  [[noreturn]] void Fail(const std::string& expected, const std::string& got) const;
  std::string OpName() const;

  // Input.
  size_t Remaining() const { return in_.size() - pos_; }
  void Need(uint64_t n) const;
  uint64_t ReadLE(int bytes);
  std::string ReadBytes(uint64_t n);
  std::string ReadLine();
  void ChargeBytes(uint64_t n);

  // Nodes and the stack. References into nodes_ are invalidated by NewNode: never
  // hold one across it.
  int NewNode(NodeKind kind);
  Node& N(int id) { return nodes_[id]; }
  void Push(int id) { stack_.push_back(id); }
  int Pop();
  int Top();
  size_t MarkBase() const { return marks_.empty() ? 0 : marks_.back(); }
  std::vector<int> PopMark();
  void Nest(int parent, int child);  // child now sits inside parent (depth limit)
  int MakeInt(int64_t v);
  int MakeFloat(double v);
  int MakeBool(bool v);
  int MakeString(NodeKind kind, std::string s);
  int MakeSequence(NodeKind kind, std::vector<int> items);  // a copy (see N())
  int MemoGet(uint64_t key);
  void Append(int target, int item);
  void SetItem(int target, int key, int value);

  // Accessors used by the understood callables.
  bool IsText(int id);
  std::string TextOf(int id, const char* what);
  const std::string& BytesOf(int id, const char* what);  // bytes or Python 2 str
  std::string LatinBytesOf(int id, const char* what);    // also text, as Latin-1
  int64_t IntOf(int id, const char* what);
  std::vector<int> TupleOf(int id, const char* what);  // a copy (see N())
  std::vector<int64_t> IntsOf(int id, const char* what);
  std::string KindName(int id) const { return DescribeNode(nodes_[id]); }

  // The opcode loop and its groups; each group returns false for opcodes not its own.
  int Execute();
  bool ScalarOpcode(uint8_t op);
  bool StringOpcode(uint8_t op);
  bool ContainerOpcode(uint8_t op);
  bool MemoOpcode(uint8_t op);
  bool ObjectOpcode(uint8_t op);
  int ReadLongBinary(uint64_t n_bytes);
  double ReadBinaryFloat();

  // Globals, REDUCE / NEWOBJ / BUILD (pickle_calls.cc).
  int MakeGlobal(const std::string& module, const std::string& name);
  int MakeDType(const std::vector<int>& args);
  void BuildDType(int id, int state);
  std::shared_ptr<NdArray> ArrayFromBytes(const std::vector<int64_t>& shape, int dtype_id,
                                          bool fortran, const std::string& raw);
  void BuildArray(int id, int state);
  int UnsupportedDType(const char* what, int dtype_id);
  int NewInstance(int cls_id);
  int Reduce(int callable, int args_id);
  int ReduceArray(const std::vector<int>& args);
  int ReduceScalar(const std::vector<int>& args);
  int ReduceFromBuffer(const std::vector<int>& args);
  int ReduceBytes(const std::vector<int>& args);
  int ReduceCodecsEncode(const std::vector<int>& args);
  int ReduceRebuildTensor(const std::vector<int>& args);
  void Build(int obj, int state);
  void BuildAttributes(int obj, int state);

  // Torch storages (pickle_torch_storage.cc).
  int PersistentLoad(int pid);
  int LoadStorageFromBytes(const std::string& saved);
  Node ReadZipStorage(const std::string& saved, const std::string& what,
                      std::string* data);
  Node ReadLegacyStorage(const std::string& saved, const std::string& what,
                         std::string* data);
  size_t SkipTorchMagic(const std::string& saved);
  void RequireSavedStorage(const Node& storage);
  std::shared_ptr<NdArray> TensorFromStorage(const TensorRef& t, const NdArray& storage);

  // Protocol 0 text arguments (pickle_text.cc).
  int64_t ParseDecimal(std::string s, const char* what);
  int HexDigit(char c);
  std::string UnquoteString(const std::string& s);  // Python repr of a str
  bool UnescapeChar(const std::string& s, size_t* i, char* out);
  std::string DecodeRawUnicode(const std::string& s);

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

}  // namespace handlabel::pickle
