#pragma once
// Small text helpers for messages and file names.

#include <string>
#include <vector>

namespace handlabel {

// "a, b, c" (separator ", " unless given).
std::string Join(const std::vector<std::string>& items,
                 const std::string& separator = ", ");

// ASCII lower case (file extensions, option values).
std::string Lower(std::string s);

}  // namespace handlabel
