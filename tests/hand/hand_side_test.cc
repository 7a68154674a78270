#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "hand/hand_model.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

TEST(HandSide, NamesRoundTrip) {
  EXPECT_EQ(HandSideName(HandSide::kRight), "right");
  EXPECT_EQ(HandSideName(HandSide::kLeft), "left");
  for (const HandSide side : {HandSide::kRight, HandSide::kLeft}) {
    EXPECT_EQ(HandSideFromName(HandSideName(side)), side);
    EXPECT_EQ(ParseHandSide(HandSideName(side), "x", "side"), side);
  }
}

TEST(HandSide, OnlyTheExactSpellingsParse) {
  for (const char* text : {"", "Left", "RIGHT", " left", "both"}) {
    EXPECT_FALSE(HandSideFromName(text).has_value()) << text;
  }
  const std::string error =
      testing::InputErrorOf([] { ParseHandSide("both", "label.json", "hand_side"); });
  EXPECT_THAT(error, HasSubstr("label.json"));
  EXPECT_THAT(error, HasSubstr("hand_side"));
  EXPECT_THAT(error, HasSubstr("\"right\" or \"left\", got both"));
}

}  // namespace
}  // namespace handlabel
