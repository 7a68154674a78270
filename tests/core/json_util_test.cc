#include "core/json_util.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

TEST(JsonUtil, StrictParseRefusesRepeatedKeysAtAnyDepth) {
  EXPECT_EQ(ParseJsonStrict(R"({"a": 1, "b": {"a": 2}})", "f.json")["b"]["a"], 2);
  // The same key in sibling objects is fine; twice in one object is not.
  EXPECT_NO_THROW(ParseJsonStrict(R"([{"a": 1}, {"a": 2}])", "f.json"));
  std::string error =
      testing::InputErrorOf([] { ParseJsonStrict(R"({"a": 1, "a": 2})", "f.json"); });
  EXPECT_THAT(error, HasSubstr("f.json"));
  EXPECT_THAT(error, HasSubstr("'a'"));
  EXPECT_THAT(error, HasSubstr("each key once"));
  error = testing::InputErrorOf(
      [] { ParseJsonStrict(R"({"x": [{"k": 1, "y": {"z": 1, "z": 1}}]})", "g.json"); });
  EXPECT_THAT(error, HasSubstr("'z'"));
  error = testing::InputErrorOf([] { ParseJsonStrict("{\"a\": ", "h.json"); });
  EXPECT_THAT(error, HasSubstr("h.json"));
  EXPECT_THAT(error, HasSubstr("valid JSON"));
}

TEST(JsonUtil, UnknownKeysAreNamedWithTheKnownOnes) {
  const nlohmann::json j = {{"width", 1}, {"hieght", 2}};
  const std::string error = testing::InputErrorOf([&] {
    RejectUnknownKeys(j, {"width", "height"}, "rig.json", "cameras[0].");
  });
  EXPECT_THAT(error, HasSubstr("rig.json"));
  EXPECT_THAT(error, HasSubstr("cameras[0].hieght"));
  EXPECT_THAT(error, HasSubstr("width, height"));
  EXPECT_NO_THROW(RejectUnknownKeys(j, {"width", "hieght"}, "rig.json"));
}

}  // namespace
}  // namespace handlabel
