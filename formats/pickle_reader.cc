#include "formats/pickle_reader.h"

#include <cstdio>
#include <sstream>

#include "core/errors.h"
#include "core/file_bytes.h"
#include "core/option_checks.h"
#include "formats/pickle_machine.h"
#include "formats/utf8.h"

namespace handlabel {
namespace pickle {

PickleValue PickleMachine::Run() {
  const int root = Execute();
  return ConvertPickleGraph(nodes_, root, source_, limits_);
}

// ---- errors ------------------------------------------------------------------------

void PickleMachine::Fail(const std::string& expected, const std::string& got) const {
  throw InputError(
      source_, "pickle", expected,
      got + " (opcode " + OpName() + " at offset " + std::to_string(op_offset_) + ")");
}

std::string PickleMachine::OpName() const {
  const char* name = PickleOpcodeName(op_);
  if (name) return name;
  char hex[8];
  std::snprintf(hex, sizeof(hex), "0x%02x", op_);
  return hex;
}

// ---- input -------------------------------------------------------------------------

void PickleMachine::Need(uint64_t n) const {
  if (n > Remaining()) {
    Fail(std::to_string(n) + " more bytes",
         "only " + std::to_string(Remaining()) + " left (truncated pickle)");
  }
}

uint64_t PickleMachine::ReadLE(int bytes) {
  Need(bytes);
  uint64_t v = 0;
  for (int k = bytes - 1; k >= 0; --k) v = (v << 8) | static_cast<uint8_t>(in_[pos_ + k]);
  pos_ += bytes;
  return v;
}

std::string PickleMachine::ReadBytes(uint64_t n) {
  Need(n);
  ChargeBytes(n);
  std::string s = in_.substr(pos_, static_cast<size_t>(n));
  pos_ += static_cast<size_t>(n);
  return s;
}

std::string PickleMachine::ReadLine() {
  const size_t end = in_.find('\n', pos_);
  if (end == std::string::npos) Fail("a newline-terminated argument", "end of data");
  std::string s = in_.substr(pos_, end - pos_);
  pos_ = end + 1;
  return s;
}

void PickleMachine::ChargeBytes(uint64_t n) {
  total_bytes_ += static_cast<int64_t>(n);
  if (total_bytes_ > limits_.max_total_bytes) {
    Fail("at most " + std::to_string(limits_.max_total_bytes) + " bytes of data", "more");
  }
}

// ---- nodes and stack ---------------------------------------------------------------

int PickleMachine::NewNode(NodeKind kind) {
  if (static_cast<int64_t>(nodes_.size()) >= limits_.max_values) {
    Fail("at most " + std::to_string(limits_.max_values) + " values", "more");
  }
  nodes_.emplace_back();
  nodes_.back().kind = kind;
  return static_cast<int>(nodes_.size()) - 1;
}

int PickleMachine::Pop() {
  if (stack_.size() <= MarkBase()) Fail("a value on the stack", "an empty stack");
  const int id = stack_.back();
  stack_.pop_back();
  return id;
}

int PickleMachine::Top() {
  if (stack_.size() <= MarkBase()) Fail("a value on the stack", "an empty stack");
  return stack_.back();
}

std::vector<int> PickleMachine::PopMark() {
  if (marks_.empty()) Fail("a MARK before this opcode", "none");
  const size_t base = marks_.back();
  marks_.pop_back();
  std::vector<int> items(stack_.begin() + base, stack_.end());
  stack_.resize(base);
  return items;
}

void PickleMachine::Nest(int parent, int child) {
  const int depth = N(child).depth + 1;
  if (depth > N(parent).depth) N(parent).depth = depth;
  if (N(parent).depth > limits_.max_depth) {
    Fail("nesting at most " + std::to_string(limits_.max_depth) + " levels deep",
         "deeper nesting");
  }
}

int PickleMachine::MakeInt(int64_t v) {
  const int id = NewNode(NodeKind::kInt);
  N(id).integer = v;
  return id;
}

int PickleMachine::MakeFloat(double v) {
  const int id = NewNode(NodeKind::kFloat);
  N(id).real = v;
  return id;
}

int PickleMachine::MakeBool(bool v) {
  const int id = NewNode(NodeKind::kBool);
  N(id).boolean = v;
  return id;
}

int PickleMachine::MakeString(NodeKind kind, std::string s) {
  const int id = NewNode(kind);
  N(id).text = std::move(s);
  return id;
}

int PickleMachine::MakeSequence(NodeKind kind, std::vector<int> items) {
  const int id = NewNode(kind);
  for (int item : items) Nest(id, item);
  N(id).items = items;
  return id;
}

int PickleMachine::MemoGet(uint64_t key) {
  const auto it = memo_.find(key);
  if (it == memo_.end()) Fail("a stored memo entry", "memo key " + std::to_string(key));
  return it->second;
}

void PickleMachine::Append(int target, int item) {
  const NodeKind k = N(target).kind;
  if (k != NodeKind::kList && k != NodeKind::kSet) {
    Fail("a list or set to append to", KindName(target));
  }
  Nest(target, item);
  N(target).items.push_back(item);
}

void PickleMachine::SetItem(int target, int key, int value) {
  if (N(target).kind != NodeKind::kDict) Fail("a dict to set items on", KindName(target));
  Nest(target, key);
  Nest(target, value);
  N(target).entries.emplace_back(key, value);
}

// ---- accessors used by the understood callables ------------------------------------

bool PickleMachine::IsText(int id) {
  const NodeKind k = N(id).kind;
  return k == NodeKind::kText || k == NodeKind::kPy2Str;
}

std::string PickleMachine::TextOf(int id, const char* what) {
  if (N(id).kind == NodeKind::kText) return N(id).text;
  if (N(id).kind == NodeKind::kPy2Str) return Latin1ToUtf8(N(id).text);
  Fail(std::string(what) + " as a string", KindName(id));
}

const std::string& PickleMachine::BytesOf(int id, const char* what) {
  const NodeKind k = N(id).kind;
  if (k == NodeKind::kBytes || k == NodeKind::kPy2Str) return N(id).text;
  Fail(std::string(what) + " as bytes", KindName(id));
}

// Python 3 pickles of Python 2 buffers arrive as str when loaded with latin1.
std::string PickleMachine::LatinBytesOf(int id, const char* what) {
  if (N(id).kind != NodeKind::kText) return BytesOf(id, what);
  std::string raw;
  if (!Utf8ToLatin1(N(id).text, &raw)) Fail(std::string(what), "non-Latin-1 text");
  return raw;
}

int64_t PickleMachine::IntOf(int id, const char* what) {
  if (N(id).kind == NodeKind::kInt) return N(id).integer;
  if (N(id).kind == NodeKind::kBool) return N(id).boolean;
  Fail(std::string(what) + " as an integer", KindName(id));
}

std::vector<int> PickleMachine::TupleOf(int id, const char* what) {
  const NodeKind k = N(id).kind;
  if (k == NodeKind::kTuple || k == NodeKind::kList) return N(id).items;
  Fail(std::string(what) + " as a tuple", KindName(id));
}

std::vector<int64_t> PickleMachine::IntsOf(int id, const char* what) {
  std::vector<int64_t> v;
  for (int item : TupleOf(id, what)) v.push_back(IntOf(item, what));
  return v;
}

// ---- the opcode loop ---------------------------------------------------------------

int PickleMachine::Execute() {
  while (true) {
    op_offset_ = pos_;
    if (pos_ >= in_.size()) {
      op_ = 0;
      Fail("a STOP opcode", "end of data (truncated pickle)");
    }
    op_ = static_cast<uint8_t>(in_[pos_++]);
    if (op_ == '.') return Pop();  // STOP
    if (!ScalarOpcode(op_) && !StringOpcode(op_) && !ContainerOpcode(op_) &&
        !MemoOpcode(op_) && !ObjectOpcode(op_)) {
      Fail("a pickle opcode", "unknown opcode");
    }
    if (marks_.size() > static_cast<size_t>(limits_.max_values)) {
      Fail("fewer MARKs", "too many");
    }
  }
}

}  // namespace pickle

void PickleLimits::Check(const std::string& source) const {
  // The fields name the struct: `source` is the pickle, which has no such fields.
  RequireAtLeast(source, "PickleLimits.max_values", max_values, 1);
  RequireAtLeast(source, "PickleLimits.max_depth", max_depth, 1);
  RequireAtLeast(source, "PickleLimits.max_total_bytes", max_total_bytes, 0);
}

PickleValue ReadPickle(const std::string& bytes, const std::string& source,
                       const PickleLimits& limits) {
  limits.Check(source);
  return pickle::PickleMachine(bytes, source, limits).Run();
}

PickleValue ReadPickleFile(const std::string& path, const PickleLimits& limits) {
  return ReadPickle(ReadFileBytes(path, "pickle file"), path, limits);
}

}  // namespace handlabel
