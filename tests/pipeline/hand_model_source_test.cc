#include "pipeline/hand_model_source.h"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace handlabel
