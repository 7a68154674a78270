// The pickle opcodes (protocols 0-5), one group per function; see pickle_machine.h.
#include <cstdlib>
#include <cstring>

#include "formats/pickle_machine.h"

namespace handlabel::pickle {

bool PickleMachine::ScalarOpcode(uint8_t op) {
  switch (op) {
    case 0x80: {  // PROTO
      const uint64_t proto = ReadLE(1);
      if (proto > 5) Fail("pickle protocol 0-5", "protocol " + std::to_string(proto));
      return true;
    }
    case 0x95:  // FRAME: only a read-ahead hint
      ReadLE(8);
      return true;
    case 'N':
      Push(NewNode(NodeKind::kNone));
      return true;
    case 0x88:  // NEWTRUE
    case 0x89:  // NEWFALSE
      Push(MakeBool(op == 0x88));
      return true;
    case 'I': {  // INT; "00" and "01" are protocol 0's False and True
      const std::string line = ReadLine();
      const bool is_bool = line == "00" || line == "01";
      Push(is_bool ? MakeBool(line == "01") : MakeInt(ParseDecimal(line, "INT")));
      return true;
    }
    case 'L':
      Push(MakeInt(ParseDecimal(ReadLine(), "LONG")));
      return true;
    case 'J':
      Push(MakeInt(static_cast<int32_t>(ReadLE(4))));
      return true;
    case 'K':
      Push(MakeInt(static_cast<int64_t>(ReadLE(1))));
      return true;
    case 'M':
      Push(MakeInt(static_cast<int64_t>(ReadLE(2))));
      return true;
    case 0x8a:  // LONG1
    case 0x8b:  // LONG4
      Push(ReadLongBinary(ReadLE(op == 0x8a ? 1 : 4)));
      return true;
    case 'F': {
      const std::string line = ReadLine();
      char* end = nullptr;
      const double v = std::strtod(line.c_str(), &end);
      if (line.empty() || *end != '\0') Fail("a float", "'" + line.substr(0, 40) + "'");
      Push(MakeFloat(v));
      return true;
    }
    case 'G':
      Push(MakeFloat(ReadBinaryFloat()));
      return true;
    default:
      return false;
  }
}

// LONG1 / LONG4 payload: little-endian two's complement of n_bytes bytes.
int PickleMachine::ReadLongBinary(uint64_t n_bytes) {
  if (n_bytes > 8) {
    Fail("an integer of at most 8 bytes", std::to_string(n_bytes) + " bytes");
  }
  Need(n_bytes);
  uint64_t v = 0;
  for (uint64_t k = n_bytes; k-- > 0;) v = (v << 8) | static_cast<uint8_t>(in_[pos_ + k]);
  if (n_bytes > 0 && n_bytes < 8 &&
      (static_cast<uint8_t>(in_[pos_ + n_bytes - 1]) & 0x80)) {
    v |= ~uint64_t{0} << (8 * n_bytes);  // sign-extend
  }
  pos_ += n_bytes;
  return MakeInt(static_cast<int64_t>(v));
}

// BINFLOAT: a big-endian IEEE double.
double PickleMachine::ReadBinaryFloat() {
  Need(8);
  uint64_t bits = 0;
  for (int k = 0; k < 8; ++k) bits = (bits << 8) | static_cast<uint8_t>(in_[pos_ + k]);
  pos_ += 8;
  double v;
  std::memcpy(&v, &bits, 8);
  return v;
}

bool PickleMachine::StringOpcode(uint8_t op) {
  switch (op) {
    case 'S':
      Push(MakeString(NodeKind::kPy2Str, UnquoteString(ReadLine())));
      return true;
    case 'T':
      Push(MakeString(NodeKind::kPy2Str, ReadBytes(ReadLE(4))));
      return true;
    case 'U':
      Push(MakeString(NodeKind::kPy2Str, ReadBytes(ReadLE(1))));
      return true;
    case 'V':
      Push(MakeString(NodeKind::kText, DecodeRawUnicode(ReadLine())));
      return true;
    case 'X':
      Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(4))));
      return true;
    case 0x8c:
      Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(1))));
      return true;
    case 0x8d:
      Push(MakeString(NodeKind::kText, ReadBytes(ReadLE(8))));
      return true;
    case 'B':
      Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(4))));
      return true;
    case 'C':
      Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(1))));
      return true;
    case 0x8e:
    case 0x96:
      Push(MakeString(NodeKind::kBytes, ReadBytes(ReadLE(8))));
      return true;
    case 0x98:  // READONLY_BUFFER: no effect on our values
      Top();
      return true;
    default:
      return false;
  }
}

bool PickleMachine::ContainerOpcode(uint8_t op) {
  switch (op) {
    case '(':
      marks_.push_back(stack_.size());
      return true;
    case '0':
      Pop();
      return true;
    case '1':
      PopMark();
      return true;
    case '2':
      Push(Top());
      return true;
    case ')':
      Push(NewNode(NodeKind::kTuple));
      return true;
    case ']':
      Push(NewNode(NodeKind::kList));
      return true;
    case '}':
      Push(NewNode(NodeKind::kDict));
      return true;
    case 0x8f:
      Push(NewNode(NodeKind::kSet));
      return true;
    case 't':
      Push(MakeSequence(NodeKind::kTuple, PopMark()));
      return true;
    case 'l':
      Push(MakeSequence(NodeKind::kList, PopMark()));
      return true;
    case 0x91:
      Push(MakeSequence(NodeKind::kSet, PopMark()));
      return true;
    case 0x85:
    case 0x86:
    case 0x87: {  // TUPLE1-3
      std::vector<int> items(op - 0x84);
      for (size_t k = items.size(); k-- > 0;) items[k] = Pop();
      Push(MakeSequence(NodeKind::kTuple, items));
      return true;
    }
    case 'd':    // DICT: a new dict of the MARKed pairs
    case 'u': {  // SETITEMS: the MARKed pairs into the dict below the MARK
      const std::vector<int> items = PopMark();
      if (items.size() % 2) Fail("key-value pairs", "an odd number of items");
      const int target = op == 'd' ? NewNode(NodeKind::kDict) : Top();
      for (size_t k = 0; k < items.size(); k += 2)
        SetItem(target, items[k], items[k + 1]);
      if (op == 'd') Push(target);
      return true;
    }
    case 'a': {
      const int item = Pop();
      Append(Top(), item);
      return true;
    }
    case 'e':
    case 0x90: {
      const std::vector<int> items = PopMark();
      const int target = Top();
      for (int item : items) Append(target, item);
      return true;
    }
    case 's': {
      const int value = Pop();
      const int key = Pop();
      SetItem(Top(), key, value);
      return true;
    }
    default:
      return false;
  }
}

bool PickleMachine::MemoOpcode(uint8_t op) {
  switch (op) {
    case 'g':
      Push(MemoGet(static_cast<uint64_t>(ParseDecimal(ReadLine(), "GET"))));
      return true;
    case 'h':
      Push(MemoGet(ReadLE(1)));
      return true;
    case 'j':
      Push(MemoGet(ReadLE(4)));
      return true;
    case 'p':
      memo_[static_cast<uint64_t>(ParseDecimal(ReadLine(), "PUT"))] = Top();
      return true;
    case 'q':
      memo_[ReadLE(1)] = Top();
      return true;
    case 'r':
      memo_[ReadLE(4)] = Top();
      return true;
    case 0x94:  // MEMOIZE
      memo_[memo_.size()] = Top();
      return true;
    default:
      return false;
  }
}

bool PickleMachine::ObjectOpcode(uint8_t op) {
  switch (op) {
    case 'c': {
      const std::string module = ReadLine();
      const std::string name = ReadLine();
      Push(MakeGlobal(module, name));
      return true;
    }
    case 0x93: {  // STACK_GLOBAL
      const int name = Pop();
      const int module = Pop();
      if (N(name).kind != NodeKind::kText || N(module).kind != NodeKind::kText) {
        Fail("module and name strings", "other values");
      }
      const std::string module_name = N(module).text, global_name = N(name).text;
      Push(MakeGlobal(module_name, global_name));
      return true;
    }
    case 'R': {
      const int args = Pop();
      const int callable = Pop();
      Push(Reduce(callable, args));
      return true;
    }
    case 0x81: {  // NEWOBJ
      const int args = Pop();
      const int cls = Pop();
      TupleOf(args, "NEWOBJ arguments");
      Push(NewInstance(cls));
      return true;
    }
    case 0x92:  // NEWOBJ_EX
      Pop();    // kwargs
      Pop();    // args
      Push(NewInstance(Pop()));
      return true;
    case 'i': {  // INST module\nname\n with MARKed args
      const std::string module = ReadLine();
      const std::string name = ReadLine();
      PopMark();
      Push(NewInstance(MakeGlobal(module, name)));
      return true;
    }
    case 'o': {  // OBJ: MARK cls args...
      const std::vector<int> items = PopMark();
      if (items.empty()) Fail("a class after MARK", "nothing");
      Push(NewInstance(items[0]));
      return true;
    }
    case 'b': {
      const int state = Pop();
      Build(Top(), state);
      return true;
    }
    case 'Q':
      Push(PersistentLoad(Pop()));
      return true;
    case 'P':
      Fail("torch storage persistent ids (BINPERSID)", "a text persistent id");
    case 0x82:
    case 0x83:
    case 0x84:
      Fail("no extension registry codes", "an EXT opcode");
    case 0x97:
      Fail("in-band data", "an out-of-band buffer");
    default:
      return false;
  }
}

}  // namespace handlabel::pickle
