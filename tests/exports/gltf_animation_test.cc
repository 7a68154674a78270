#include "exports/gltf_animation.h"

#include <gtest/gtest.h>

#include <cstring>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_lbs.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

// Two labels of the capsule hand, posed by PoseHand as a fit writes them.
LabelSeries TwoLabels(const HandModel& model) {
  LabelSeries series;
  series.labels_dir = "/labels";
  for (int k = 0; k < 2; ++k) {
    LabelRecord label;
    label.frame = "f" + std::to_string(k);
    HandParams params;
    params.global_orient = Eigen::Vector3d(0.2 * k, -0.1, 0.3);
    params.hand_pose.setConstant(0.1 * (k + 1));
    params.transl = Eigen::Vector3d(0.01, 0.02 * k, 0.5);
    label.mesh = PoseHand(model, params);
    label.params = params;
    series.labels.push_back(label);
  }
  return series;
}

nlohmann::json JsonChunk(const std::string& glb) {
  uint32_t length = 0;
  std::memcpy(&length, glb.data() + 12, 4);
  return nlohmann::json::parse(glb.substr(20, length));
}

TEST(GltfAnimation, OneKeyframeAndTargetPerLabelInAValidContainer) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  const std::string glb = HandAnimationGlb(TwoLabels(model), model, {});
  ASSERT_GT(glb.size(), 20u);
  EXPECT_EQ(glb.substr(0, 4), "glTF");
  uint32_t version = 0, length = 0;
  std::memcpy(&version, glb.data() + 4, 4);
  std::memcpy(&length, glb.data() + 8, 4);
  EXPECT_EQ(version, 2u);
  EXPECT_EQ(length, glb.size());
  const nlohmann::json doc = JsonChunk(glb);
  EXPECT_EQ(doc["nodes"].size(), 2u + kNumHandJoints);
  EXPECT_EQ(doc["meshes"][0]["primitives"][0]["targets"].size(), 2u);
  EXPECT_EQ(doc["meshes"][0]["extras"]["targetNames"], nlohmann::json({"f0", "f1"}));
  // Rotation and translation per joint, plus the morph weights.
  EXPECT_EQ(doc["animations"][0]["channels"].size(), 2u * kNumHandJoints + 1);
  const int times = doc["animations"][0]["samplers"][0]["input"];
  EXPECT_EQ(doc["accessors"][times]["count"], 2);
  EXPECT_FLOAT_EQ(doc["accessors"][times]["max"][0].get<float>(), 1.0f / 30);  // float32
}

TEST(GltfAnimation, LabelsWithoutParametersAndBadRatesAreNamed) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  LabelSeries series = TwoLabels(model);
  series.labels[1].params.reset();
  std::string message =
      testing::InputErrorOf([&] { HandAnimationGlb(series, model, {}); });
  EXPECT_NE(message.find("/labels/f1.json"), std::string::npos) << message;
  EXPECT_NE(message.find("mano"), std::string::npos) << message;
  GltfAnimationOptions options;
  options.fps = 0;
  message =
      testing::InputErrorOf([&] { HandAnimationGlb(TwoLabels(model), model, options); });
  EXPECT_NE(message.find("fps"), std::string::npos) << message;
}

}  // namespace
}  // namespace handlabel
