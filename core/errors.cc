#include "core/errors.h"

namespace handlabel {
namespace {

std::string FormatInputError(const std::string& source, const std::string& field,
                             const std::string& expected, const std::string& got) {
  std::string message = source + ": ";
  if (!field.empty()) message += "field '" + field + "': ";
  message += "expected " + expected;
  if (!got.empty()) message += ", got " + got;
  return message;
}

}  // namespace

InputError::InputError(const std::string& source, const std::string& field,
                       const std::string& expected, const std::string& got)
    : Error(FormatInputError(source, field, expected, got)),
      source_(source),
      field_(field),
      expected_(expected),
      got_(got) {}

void FailCheck(const char* condition, const char* file, int line,
               const std::string& detail) {
  throw Error(std::string("internal check failed: ") + condition + " at " + file + ":" +
              std::to_string(line) + (detail.empty() ? "" : " (" + detail + ")"));
}

}  // namespace handlabel
