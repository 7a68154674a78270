#include "hand/hand_params_json.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <tuple>

#include "tests/test_util.h"

namespace handlabel {
namespace {

using ::testing::HasSubstr;

// `fit --init` with 1e300 parameters used to run and print MPJPE -nan.
TEST(HandParamsJson, ValuesOutsidePlausibleRangesAreRefused) {
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
