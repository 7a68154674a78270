#include "exports/mano_convention.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

HandModel ModelWithMean() {
  HandModel model = MakeCapsuleHand(HandSide::kRight);
  model.pose_mean = Eigen::VectorXd::LinSpaced(kNumPoseParams, -0.4, 0.5);
  return model;
}

TEST(ManoConvention, LayerDefaultsAreTheLibrariesOwn) {
  EXPECT_FALSE(DefaultFlatHandMean(ManoConvention::kSmplx));     // smplx.MANO
  EXPECT_TRUE(DefaultFlatHandMean(ManoConvention::kManopth));    // manopth.ManoLayer
  EXPECT_TRUE(DefaultFlatHandMean(ManoConvention::kManotorch));  // manotorch's ManoLayer
  EXPECT_EQ(ParseManoConvention("manopth", "--x"), ManoConvention::kManopth);
  EXPECT_EQ(ParseManoConvention("manotorch", "--x"), ManoConvention::kManotorch);
  EXPECT_EQ(ToString(ParseManoConvention("smplx", "--x")), "smplx");
  EXPECT_EQ(ToString(ManoConvention::kManotorch), "manotorch");
  EXPECT_NE(testing::InputErrorOf([] {
              ParseManoConvention("smpl", "--x");
            }).find("smplx | manopth | manotorch"),
            std::string::npos);
}

TEST(ManoConvention, LayerThatAddsTheMeanGetsItTakenOff) {
  const HandModel model = ModelWithMean();
  HandParams label;
  label.hand_pose = Eigen::VectorXd::LinSpaced(kNumPoseParams, 0.3, -0.2);
  EXPECT_EQ(LayerHandPose(label, model, true), label.hand_pose);
  const Eigen::Matrix<double, kNumPoseParams, 1> given =
      LayerHandPose(label, model, false);
  // What the layer poses: given + hands_mean = the label's rotations.
  EXPECT_LT((given + model.pose_mean - label.hand_pose).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_GT((given - label.hand_pose).cwiseAbs().maxCoeff(), 0.1);
}

TEST(ManoConvention, MissingMeanIsNamed) {
  HandModel model = ModelWithMean();
  model.pose_mean.resize(0);
  const std::string message =
      testing::InputErrorOf([&] { LayerHandPose(HandParams(), model, false); });
  EXPECT_NE(message.find("hands_mean"), std::string::npos) << message;
  EXPECT_NE(message.find("flat_hand_mean true"), std::string::npos) << message;
}

}  // namespace
}  // namespace handlabel
