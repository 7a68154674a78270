#include "pipeline/hand_model_source.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>

#include "core/errors.h"
#include "core/hand_model_io.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

std::string ManoFixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/mano/" + name;
}

// The fixture model converted to the own format (which records side and tips).
std::string OwnModelFile(HandSide side) {
  HandModelLoadOptions options;
  options.tip_vertex_ids = std::array<int, 5>{1, 7, 5, 8, 6};
  options.side = side;
  const std::string path = testing::ScratchDir() + "/model.npz";
  SaveHandModel(LoadHandModel(ManoFixture("mano_smplx_right.npz"), options), path);
  return path;
}

TEST(HandModelSource, LoadsModelFilesGivenByFlag) {
  const std::string path = OwnModelFile(HandSide::kLeft);
  const ResolvedHandModel r = ResolveHandModel(path, HandSide::kLeft);
  EXPECT_EQ(r.source, path);
  EXPECT_EQ(r.model.side, HandSide::kLeft);
  EXPECT_EQ(r.model.num_vertices(), 12);
}

TEST(HandModelSource, RefusesAModelOfTheOtherSide) {
  const std::string path = OwnModelFile(HandSide::kRight);
  try {
    ResolveHandModel(path, HandSide::kLeft);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--hand-model"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("a left hand model"), std::string::npos)
        << e.what();
  }
}

TEST(HandModelSource, BadModelFilesNameTheFileAndKey) {
  // A MANO-style pickle of 12 vertices has no default fingertips.
  try {
    ResolveHandModel(ManoFixture("mano_py2_right.pkl"), HandSide::kRight);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "tip_vertex_ids");
    EXPECT_NE(std::string(e.what()).find("mano_py2_right.pkl"), std::string::npos);
  }
}

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
