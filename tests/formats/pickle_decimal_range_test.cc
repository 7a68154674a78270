// Protocol-0 INT / LONG text arguments at and beyond the int64 range (found by the
// UndefinedBehaviorSanitizer build: -9223372036854775808 was negated as an int64_t, and
// magnitudes from 2^63 up to 2^64 - 1 wrapped silently, 18446744073709551615 to -1).

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>
#include <string>

#include "core/errors.h"
#include "formats/pickle_reader.h"

namespace handlabel {
namespace {

// `digits` as a protocol-0 INT ("I...\n.") and LONG ("L...L\n."); the value, which must
// agree, or the error of the INT form.
int64_t ReadDecimal(const std::string& digits) {
  const PickleValue as_int = ReadPickle("I" + digits + "\n.", "int.pkl");
  const PickleValue as_long = ReadPickle("L" + digits + "L\n.", "long.pkl");
  EXPECT_EQ(as_int.kind, PickleValue::Kind::kInt);
  EXPECT_EQ(as_long.integer, as_int.integer) << digits;
  return as_int.integer;
}

std::string DecimalError(const std::string& digits) {
  try {
    ReadPickle("I" + digits + "\n.", "int.pkl");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(PickleDecimalRange, EndsOfTheInt64RangeReadExactly) {
  EXPECT_EQ(ReadDecimal("9223372036854775807"), std::numeric_limits<int64_t>::max());
  EXPECT_EQ(ReadDecimal("-9223372036854775808"), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(ReadDecimal("-9223372036854775807"), -std::numeric_limits<int64_t>::max());
  EXPECT_EQ(ReadDecimal("+42"), 42);
  EXPECT_EQ(ReadDecimal("-0"), 0);
  EXPECT_EQ(ReadDecimal("000000000000000000000000000123"), 123);
}

TEST(PickleDecimalRange, MagnitudesBeyondInt64AreRefusedNotWrapped) {
  for (const char* digits :
       {"9223372036854775808", "-9223372036854775809", "18446744073709551615",
        "18446744073709551616", "99999999999999999999999"}) {
    const std::string error = DecimalError(digits);
    EXPECT_NE(error.find("int.pkl"), std::string::npos) << digits << ": " << error;
    EXPECT_NE(error.find("an integer that fits 64 bits"), std::string::npos)
        << digits << ": " << error;
  }
}

}  // namespace
}  // namespace handlabel
