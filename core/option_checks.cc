#include "core/option_checks.h"

#include <charconv>
#include <cmath>

namespace handlabel {
namespace option_checks_internal {

std::string FloatText(double value) {
  // "-nan" and "nan" would tell the user the same thing; one spelling is easier to grep.
  if (std::isnan(value)) return "nan";
  // The shortest text that reads back as this double: "0.1" rather than to_string's
  // "0.100000", and "1e-09" rather than "0.000000" for a tiny tolerance. Plain digits
  // for everyday magnitudes ("100000", not the shorter "1e+05").
  const double magnitude = std::fabs(value);
  const bool everyday = magnitude == 0 || (magnitude >= 1e-4 && magnitude < 1e15);
  char text[64];
  const std::to_chars_result r =
      everyday ? std::to_chars(text, text + sizeof(text), value, std::chars_format::fixed)
               : std::to_chars(text, text + sizeof(text), value);
  return std::string(text, r.ptr);
}

}  // namespace option_checks_internal
}  // namespace handlabel
