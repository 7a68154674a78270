#include <gtest/gtest.h>

#include <array>
#include <string>

#include "hand/hand_model_io.h"

#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::RunHandlabelCommand;

std::string ManoFixture(const std::string& name) {
  return std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/mano/" + name;
}

// tip_vertex_ids of tests/data/mano/expected.json
std::string FixtureTips() { return "1,7,5,8,6"; }

TEST(ModelCommand, InfoPrintsCountsSideAndKeypointMap) {
  const auto r = RunHandlabelCommand(
      {"model", "info", ManoFixture("mano_py2_right.pkl"), "--tips", FixtureTips()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("MANO pickle"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("side:          right"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("vertices:      12"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("betas:         10"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("45 components, with hand mean"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("thumb_tip   <- tip vertex 1"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("wrist to middle fingertip"), std::string::npos) << r.out;
}

TEST(ModelCommand, ConvertWritesTheOwnFormatThatInfoReadsWithoutOptions) {
  const std::string out = testing::ScratchDir() + "/hand.npz";
  auto r = RunHandlabelCommand({"model", "convert", ManoFixture("mano_py2_right.pkl"),
                                out, "--tips", FixtureTips(), "--side", "left"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("wrote " + out), std::string::npos) << r.out;
  r = RunHandlabelCommand({"model", "info", out});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("handlabel model npz"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("side:          left"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("name:          mano_py2_right"), std::string::npos) << r.out;
}

TEST(ModelCommand, ErrorsAndUsage) {
  auto r = RunHandlabelCommand({"model", "info", ManoFixture("mano_py2_right.pkl")});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("tip_vertex_ids"), std::string::npos) << r.err;
  r = RunHandlabelCommand({"model", "info", "/nonexistent/MANO_RIGHT.pkl"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("/nonexistent/MANO_RIGHT.pkl"), std::string::npos) << r.err;
  EXPECT_EQ(RunHandlabelCommand({"model"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"model", "frobnicate"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"model", "info"}).status, 2);
  EXPECT_EQ(RunHandlabelCommand({"model", "info", "x", "--side", "up"}).status, 2);
  r = RunHandlabelCommand({"model", "--help"});
  EXPECT_EQ(r.status, 0);
  EXPECT_NE(r.out.find("convert"), std::string::npos);
  EXPECT_EQ(RunHandlabelCommand({"model", "convert", "--help"}).status, 0);
}

// Files that record their side and fingertips: --side and --tips used to be ignored
// (a right hand written for --side left). The other side mirrors the model.
TEST(ModelCommand, ConvertHonoursSideAndTipsForFilesThatRecordThem) {
  const std::string dir = testing::ScratchDir();
  auto r = RunHandlabelCommand({"model", "convert", ManoFixture("mano_py2_right.pkl"),
                                dir + "/right.npz", "--tips", FixtureTips()});
  ASSERT_EQ(r.status, 0) << r.err;
  r = RunHandlabelCommand({"model", "convert", dir + "/right.npz", dir + "/left.npz",
                           "--side", "left", "--tips", "2,3,4,5,6"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("mirrored"), std::string::npos) << r.out;
  const HandModel right = LoadHandModel(dir + "/right.npz");
  const HandModel left = LoadHandModel(dir + "/left.npz");
  EXPECT_EQ(right.side, HandSide::kRight);
  EXPECT_EQ(left.side, HandSide::kLeft);
  EXPECT_TRUE(left.v_template.col(0).isApprox(-right.v_template.col(0)));
  EXPECT_TRUE(left.v_template.col(1).isApprox(right.v_template.col(1)));
  EXPECT_EQ(left.tip_vertex_ids, (std::array<int, 5>{2, 3, 4, 5, 6}));
  r = RunHandlabelCommand(
      {"model", "convert", dir + "/right.npz", dir + "/bad.npz", "--tips", "1,2,3,4,99"});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("--tips"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("99"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace handlabel
