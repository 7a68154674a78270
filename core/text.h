#pragma once
// Small text helpers for messages and file names.

#include <string>
#include <vector>

namespace handlabel {

// "a, b, c" (separator ", " unless given).
std::string Join(const std::vector<std::string>& items,
                 const std::string& separator = ", ");

// `value` as an ostream prints it by default (6 significant digits, the shorter of
// fixed and exponent form: 0.25, 1e-09, 1.5e+06) for messages, where
// std::to_string's 6 fixed decimals would print 1e-9 as 0.000000.
std::string FormatNumber(double value);

// ASCII lower case (file extensions, option values).
std::string Lower(std::string s);

}  // namespace handlabel
