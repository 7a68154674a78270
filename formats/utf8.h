#pragma once
// Conversions between UTF-8, Latin-1 and code points, for numpy string arrays and
// Python 2 pickles (whose str objects are bytes read as Latin-1).

#include <cstdint>
#include <string>
#include <vector>

namespace handlabel {

void AppendUtf8(uint32_t code_point, std::string* out);
// Decodes UTF-8 into code points; bytes that are not valid UTF-8 count as Latin-1.
std::vector<uint32_t> DecodeUtf8(const std::string& s);
std::string Latin1ToUtf8(const std::string& s);
// UTF-8 text whose code points are all below 256 -> those bytes (Python's
// str.encode('latin1')); false if a code point does not fit.
bool Utf8ToLatin1(const std::string& s, std::string* out);

}  // namespace handlabel
