#include "pipeline/hand_model_source.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "core/errors.h"

namespace handlabel {
namespace {

TEST(HandModelSource, ShippedOpenHandIsTheDefaultForEachSide) {
  ::unsetenv("HANDLABEL_HAND_MODEL");
  const ResolvedHandModel right = ResolveHandModel("", HandSide::kRight);
  EXPECT_NE(right.source.find("models/open_hand_right.npz"), std::string::npos);
  EXPECT_EQ(right.model.side, HandSide::kRight);
  EXPECT_TRUE(right.note.empty());
  const ResolvedHandModel left = ResolveHandModel("", HandSide::kLeft);
  EXPECT_EQ(left.model.side, HandSide::kLeft);
}

TEST(HandModelSource, FlagBeatsEnvironmentAndCapsuleIsBuiltIn) {
  const std::string right =
      std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz";
  ::setenv("HANDLABEL_HAND_MODEL", "capsule", 1);
  EXPECT_EQ(ResolveHandModel("", HandSide::kRight).source, "builtin:capsule");
  EXPECT_EQ(ResolveHandModel(right, HandSide::kRight).source, right);
  ::unsetenv("HANDLABEL_HAND_MODEL");
  // A right-hand file when the left hand is asked for.
  try {
    ResolveHandModel(right, HandSide::kLeft);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.source(), "--hand-model");
    EXPECT_NE(std::string(e.what()).find("right hand"), std::string::npos);
  }
  EXPECT_THROW(ResolveHandModel("/nonexistent/model.npz", HandSide::kRight), InputError);
}

}  // namespace
}  // namespace handlabel
