// Protocol 0's text arguments: decimal integers, Python str reprs and
// raw-unicode-escape text.
#include <cctype>
#include <limits>

#include "formats/pickle_machine.h"
#include "formats/utf8.h"

namespace handlabel::pickle {

int64_t PickleMachine::ParseDecimal(std::string s, const char* what) {
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

int PickleMachine::HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  Fail("a hex digit", std::string("'") + c + "'");
}

// Python repr of a str: '...' or "..." with backslash escapes.
std::string PickleMachine::UnquoteString(const std::string& s) {
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
    char c;
    if (UnescapeChar(s, &i, &c)) {
      out.push_back(c);
    } else {  // an unknown escape stays as written
      out.push_back('\\');
      out.push_back(s[i]);
    }
  }
  return out;
}

// The character of the escape whose letter is s[*i] (after the backslash); leaves *i
// on its last character. False for escapes Python keeps verbatim.
bool PickleMachine::UnescapeChar(const std::string& s, size_t* i, char* out) {
  const char c = s[*i];
  switch (c) {
    case 'n':
      *out = '\n';
      return true;
    case 't':
      *out = '\t';
      return true;
    case 'r':
      *out = '\r';
      return true;
    case '\\':
    case '\'':
    case '"':
      *out = c;
      return true;
    case 'x':
      if (*i + 2 >= s.size()) Fail("\\x and two hex digits", "end");
      *out = static_cast<char>(16 * HexDigit(s[*i + 1]) + HexDigit(s[*i + 2]));
      *i += 2;
      return true;
    default:
      break;
  }
  if (c < '0' || c > '7') return false;
  int v = 0;
  for (int k = 0; k < 3 && *i < s.size() - 1 && s[*i] >= '0' && s[*i] <= '7'; ++k) {
    v = v * 8 + (s[(*i)++] - '0');
  }
  --*i;
  *out = static_cast<char>(v & 0xFF);
  return true;
}

// raw-unicode-escape: \uXXXX and \UXXXXXXXX escapes, other bytes are Latin-1.
std::string PickleMachine::DecodeRawUnicode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    size_t digits = 0;
    if (s[i] == '\\' && i + 1 < s.size()) {
      digits = s[i + 1] == 'u' ? 4 : s[i + 1] == 'U' ? 8 : 0;
    }
    if (digits == 0 || i + 2 + digits > s.size()) {
      AppendUtf8(static_cast<unsigned char>(s[i]), &out);
      continue;
    }
    uint32_t cp = 0;
    for (size_t k = 0; k < digits; ++k) {
      const char h = s[i + 2 + k];
      if (!std::isxdigit(static_cast<unsigned char>(h))) Fail("hex digits", "other");
      cp = cp * 16 + static_cast<uint32_t>(HexDigit(h));
    }
    if (cp > 0x10FFFF) Fail("a Unicode code point", "a larger number");
    AppendUtf8(cp, &out);
    i += 1 + digits;
  }
  return out;
}

}  // namespace handlabel::pickle
