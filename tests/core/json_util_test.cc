#include "core/json_util.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <tuple>

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

// `fit --init` with 1e300 parameters used to run and print MPJPE -nan.
TEST(JsonUtil, HandParametersOutsidePlausibleRangesAreRefused) {
  HandParams p;
  p.betas = Eigen::VectorXd::Zero(10);
  p.transl << 0.1, 0.2, 0.5;
  const nlohmann::json good = JsonHandParams(p);
  EXPECT_NO_THROW(HandParamsFromJson(good, "init.json"));
  for (const auto& [key, index, value] :
       std::vector<std::tuple<std::string, int, double>>{{"hand_pose", 7, 1e300},
                                                         {"global_orient", 0, -101},
                                                         {"betas", 3, 1e5},
                                                         {"transl", 2, 1e308}}) {
    nlohmann::json j = good;
    j[key][index] = value;
    const std::string error =
        testing::InputErrorOf([&] { HandParamsFromJson(j, "init.json", "params."); });
    EXPECT_THAT(error, HasSubstr("init.json"));
    EXPECT_THAT(error, HasSubstr("params." + key + "[" + std::to_string(index) + "]"));
  }
}

}  // namespace
}  // namespace handlabel
