#include "core/text.h"

#include <gtest/gtest.h>

#include <sstream>

namespace handlabel {
namespace {

TEST(Text, JoinPutsTheSeparatorBetweenItemsOnly) {
  EXPECT_EQ(Join({}), "");
  EXPECT_EQ(Join({"a"}), "a");
  EXPECT_EQ(Join({"a", "b", "c"}), "a, b, c");
  EXPECT_EQ(Join({"000001", "000007"}, ","), "000001,000007");
}

TEST(Text, FormatNumberPrintsAsAnOstreamDoes) {
  EXPECT_EQ(FormatNumber(0.25), "0.25");
  EXPECT_EQ(FormatNumber(3), "3");
  EXPECT_EQ(FormatNumber(-1.5), "-1.5");
  EXPECT_EQ(FormatNumber(1e-9), "1e-09");  // std::to_string: "0.000000"
  EXPECT_EQ(FormatNumber(1.5e6), "1.5e+06");
  EXPECT_EQ(FormatNumber(0.1234567), "0.123457");
  for (const double value : {0.015, 1.0 / 3.0, 123456789.0, -2e-300}) {
    std::ostringstream out;
    out << value;
    EXPECT_EQ(FormatNumber(value), out.str());
  }
}

}  // namespace
}  // namespace handlabel
