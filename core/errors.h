#pragma once
// Error types. Bad user input throws InputError, whose message names the source
// (file or command-line flag), the field and what was expected, so the user can fix it
// without reading our code. Internal invariants use HL_CHECK, which names the condition.

#include <stdexcept>
#include <string>

namespace handlabel {

class Error : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// "<source>: field '<field>': expected <expected>, got <got>".
class InputError : public Error {
 public:
  InputError(const std::string& source, const std::string& field,
             const std::string& expected, const std::string& got = "");
  const std::string& source() const { return source_; }
  const std::string& field() const { return field_; }
  const std::string& expected() const { return expected_; }
  const std::string& got() const { return got_; }

 private:
  std::string source_;
  std::string field_;
  std::string expected_;
  std::string got_;
};

[[noreturn]] void FailCheck(const char* condition, const char* file, int line,
                            const std::string& detail);

}  // namespace handlabel

// Invariant check that stays on in Release builds: a broken invariant must never
// turn into a wrong label.
#define HL_CHECK(cond, detail)                                              \
  do {                                                                      \
    if (!(cond)) ::handlabel::FailCheck(#cond, __FILE__, __LINE__, detail); \
  } while (0)
