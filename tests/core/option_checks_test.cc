#include "core/option_checks.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>

#include "tests/test_util.h"

namespace handlabel {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

TEST(OptionChecks, MessagesNameSourceFieldRuleAndValue) {
  EXPECT_EQ(testing::InputErrorOf([] { RequireGreater("opts", "sigma", 0.0, 0); }),
            "opts: field 'sigma': expected > 0, got 0");
  EXPECT_EQ(testing::InputErrorOf([] { RequireAtLeast("opts", "min_views", 1, 2); }),
            "opts: field 'min_views': expected >= 2, got 1");
  EXPECT_EQ(testing::InputErrorOf([] { RequireAtMost("opts", "k", 8, 7); }),
            "opts: field 'k': expected <= 7, got 8");
  EXPECT_EQ(
      testing::InputErrorOf([] { RequireInRange("opts", "jitter_deg", 46.5, 0, 45); }),
      "opts: field 'jitter_deg': expected 0..45, got 46.5");
  // A given `expected` replaces the generated rule.
  EXPECT_EQ(testing::InputErrorOf([] {
              RequireAtLeast("cli", "--threads", -1, 0, ">= 0 (0 = all cores)");
            }),
            "cli: field '--threads': expected >= 0 (0 = all cores), got -1");
}

TEST(OptionChecks, BoundsAreInclusiveWhereTheNameSaysSo) {
  EXPECT_NO_THROW(RequireAtLeast("o", "f", 2, 2));
  EXPECT_NO_THROW(RequireAtMost("o", "f", 2.0, 2));
  EXPECT_NO_THROW(RequireInRange("o", "f", 0.0, 0, 1));
  EXPECT_NO_THROW(RequireInRange("o", "f", 1.0, 0, 1));
  EXPECT_THROW(RequireGreater("o", "f", 2, 2), InputError);
  EXPECT_THROW(RequireInRange("o", "f", 1.0000001, 0, 1), InputError);
  // The bound is compared in the value's terms: no rounding of 0.4 to an integer.
  EXPECT_THROW(RequireInRange("o", "f", 0.41, 0, 0.4), InputError);
  EXPECT_THROW(RequireAtLeast("o", "f", 0, 0.5), InputError);
}

// The reason for the helpers: `if (x < 0) throw` lets NaN through.
TEST(OptionChecks, NaNFailsEveryCheck) {
  EXPECT_THROW(RequireGreater("o", "f", kNaN, 0), InputError);
  EXPECT_THROW(RequireAtLeast("o", "f", kNaN, 0), InputError);
  EXPECT_THROW(RequireAtMost("o", "f", kNaN, 0), InputError);
  EXPECT_THROW(RequireInRange("o", "f", kNaN, 0, 1), InputError);
  EXPECT_THAT(testing::InputErrorOf([] { RequireAtLeast("o", "f", -kNaN, 0); }),
              ::testing::EndsWith("got nan"));
  // Infinity is a number: only a finite bound stops it.
  EXPECT_NO_THROW(RequireGreater("o", "f", kInf, 0));
  EXPECT_THROW(RequireAtMost("o", "f", kInf, 1e300), InputError);
}

TEST(OptionChecks, ValuesReadBackAsTheyWere) {
  EXPECT_EQ(OptionValueText(3), "3");
  EXPECT_EQ(OptionValueText(int64_t{1} << 40), "1099511627776");
  EXPECT_EQ(OptionValueText(0.1), "0.1");
  EXPECT_EQ(OptionValueText(-2.0), "-2");
  EXPECT_EQ(OptionValueText(100000.0), "100000");
  EXPECT_EQ(OptionValueText(1e-9), "1e-09");
  EXPECT_EQ(OptionValueText(kInf), "inf");
  for (double v : {0.1, 1.0 / 3.0, 2e-4, 123456.789, 1e300, -7.25e-7}) {
    EXPECT_EQ(std::stod(OptionValueText(v)), v) << OptionValueText(v);
  }
}

}  // namespace
}  // namespace handlabel
