#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "hand/hand_lbs.h"
#include "hand/hand_model_io.h"
#include "hand/hand_preview.h"
#include "tests/apps/run_command.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

const std::string kModel =
    std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz";

// Reads the `v` and `f` records of an OBJ file (independent of the writer's code).
void ReadObj(const std::string& path, std::vector<Eigen::Vector3d>* vertices,
             std::vector<Eigen::Vector3i>* faces) {
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string tag;
    s >> tag;
    if (tag == "v") {
      Eigen::Vector3d v;
      s >> v.x() >> v.y() >> v.z();
      vertices->push_back(v);
    } else if (tag == "f") {
      Eigen::Vector3i f;
      s >> f.x() >> f.y() >> f.z();
      faces->push_back(f.array() - 1);  // OBJ counts from 1
    }
  }
}

TEST(ModelExportCommand, ObjHoldsThePosedAndShapedMesh) {
  const std::string out = testing::ScratchDir() + "/fist.obj";
  const auto r = testing::RunHandlabelCommand(
      {"model", "export", kModel, "--pose", "fist", "--betas", "1.5,-1", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;

  const HandModel model = LoadHandModel(kModel);
  HandParams params;
  for (const NamedHandPose& p : PreviewHandPoses(model)) {
    if (p.name == "fist") params = p.params;
  }
  params.betas = Eigen::Vector2d(1.5, -1);
  const HandMesh expected = PoseHand(model, params);

  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  ReadObj(out, &vertices, &faces);
  ASSERT_EQ(static_cast<int>(vertices.size()), model.num_vertices());
  ASSERT_EQ(static_cast<int>(faces.size()), model.num_faces());
  for (size_t i = 0; i < vertices.size(); ++i) {
    ASSERT_LT((vertices[i] - expected.vertices.row(i).transpose()).norm(), 1e-6) << i;
  }
  for (size_t i = 0; i < faces.size(); ++i) {
    ASSERT_EQ(faces[i], model.faces.row(i).transpose()) << i;
  }
}

TEST(ModelExportCommand, BadPoseOrExtensionIsAnErrorNamingIt) {
  const std::string dir = testing::ScratchDir();
  auto r = testing::RunHandlabelCommand(
      {"model", "export", kModel, "--pose", "wave", "--out", dir + "/a.ply"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find("wave"), std::string::npos) << r.err;
  r = testing::RunHandlabelCommand({"model", "export", kModel, "--out", dir + "/a.stl"});
  EXPECT_NE(r.status, 0);
  EXPECT_NE(r.err.find(".ply or .obj"), std::string::npos) << r.err;
}

TEST(ModelExportCommand, SideAndTipsAreTakenLikeModelInfo) {
  // A MANO pickle whose name records no side, with 12 vertices and no default tips.
  const std::string dir = testing::ScratchDir();
  const std::string model = dir + "/hand.pkl";
  std::filesystem::copy_file(
      std::string(HANDLABEL_SOURCE_DIR) + "/tests/data/mano/mano_py2_right.pkl", model);
  const std::string out = dir + "/hand.obj";
  auto r = testing::RunHandlabelCommand(
      {"model", "export", model, "--tips", "1,7,5,8,6", "--out", out});
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("side"), std::string::npos) << r.err;
  r = testing::RunHandlabelCommand({"model", "export", model, "--side", "left", "--tips",
                                    "1,7,5,8,6", "--pose", "fist", "--out", out});
  ASSERT_EQ(r.status, 0) << r.err;

  HandModelLoadOptions options;
  options.side = HandSide::kLeft;
  options.tip_vertex_ids = std::array<int, 5>{1, 7, 5, 8, 6};
  const HandModel loaded = LoadHandModel(model, options);
  EXPECT_EQ(loaded.side, HandSide::kLeft);
  HandParams params;
  for (const NamedHandPose& p : PreviewHandPoses(loaded)) {
    if (p.name == "fist") params = p.params;
  }
  const HandMesh expected = PoseHand(loaded, params);
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
  ReadObj(out, &vertices, &faces);
  ASSERT_EQ(static_cast<int>(vertices.size()), 12);
  for (size_t i = 0; i < vertices.size(); ++i) {
    ASSERT_LT((vertices[i] - expected.vertices.row(i).transpose()).norm(), 1e-6) << i;
  }
  EXPECT_EQ(testing::RunHandlabelCommand(
                {"model", "export", model, "--side", "up", "--out", out})
                .status,
            2);
}

}  // namespace
}  // namespace handlabel
