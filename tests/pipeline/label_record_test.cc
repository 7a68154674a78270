#include "pipeline/label_record.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>

#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "pipeline/label_policy.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

LabelRecord MakeLabel() {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  HandParams params;
  params.global_orient = testing::RandomVector3(-1, 1);
  for (int i = 0; i < kNumPoseParams; ++i) params.hand_pose[i] = testing::Gaussian(0.2);
  params.betas = Eigen::VectorXd::Zero(6);
  for (int i = 0; i < 6; ++i) params.betas[i] = testing::Gaussian(1);
  params.transl = testing::RandomVector3(-0.1, 0.1);
  LabelRecord label;
  label.frame = "subject1/seq2/000042";
  label.path = LabelPath::kRefined;
  label.params = params;
  label.mesh = PoseHand(model, params);
  label.quality.flags = {
      {"finite", true, 0, 0, "0 non-finite values"},
      {"reprojection", false, 14.5, 12, "worst view cam1: RMS 14.5 px"},
      {"view_agreement", false, std::numeric_limits<double>::infinity(), 15,
       "no keypoint seen confidently in two views"}};
  label.fit = {{"final_cost", 0.25}, {"iterations", 17}};
  label.provenance = {"poem-small", std::string(64, 'f'), model.name, "abc",
                      "0.1.0",      "deadbeef",           42};
  return label;
}

TEST(LabelRecord, JsonRoundTripKeepsEveryFieldAndPadsBetasToMano) {
  const LabelRecord label = MakeLabel();
  const nlohmann::json j = LabelToJson(label);
  EXPECT_EQ(j.at("mano").at("betas").size(), 10u);
  EXPECT_EQ(j.at("mano").at("hand_pose").size(), 45u);
  EXPECT_EQ(j.at("keypoints_3d").size(), 21u);
  EXPECT_EQ(j.at("joints_native").size(), 16u);
  EXPECT_EQ(j.at("path"), "refined");
  const LabelRecord back = LabelFromJson(nlohmann::json::parse(j.dump()), "label.json");
  EXPECT_EQ(back.frame, label.frame);
  EXPECT_EQ(back.path, label.path);
  ASSERT_TRUE(back.params.has_value());
  EXPECT_THAT(back.params->hand_pose, testing::MatrixNear(label.params->hand_pose, 0));
  EXPECT_THAT(back.params->betas.head(6), testing::MatrixNear(label.params->betas, 0));
  EXPECT_EQ(back.params->betas.tail(4).norm(), 0.0);
  EXPECT_THAT(back.mesh.vertices, testing::MatrixNear(label.mesh.vertices, 0));
  EXPECT_THAT(back.mesh.keypoints, testing::MatrixNear(label.mesh.keypoints, 0));
  ASSERT_EQ(back.quality.flags.size(), 3u);
  EXPECT_EQ(back.quality.FailedNames(), "reprojection,view_agreement");
  EXPECT_TRUE(std::isnan(back.quality.flags[2].value));  // infinity has no JSON form
  EXPECT_EQ(back.fit.at("iterations"), 17);
  EXPECT_EQ(back.provenance.seed, 42u);
  EXPECT_EQ(back.provenance.weights_sha256, std::string(64, 'f'));
  EXPECT_EQ(LabelToJson(back).at("mano").dump(), j.at("mano").dump());
}

TEST(LabelRecord, NativeJointsAreTheMatchingKeypoints) {
  const LabelRecord label = MakeLabel();
  EXPECT_THAT(NativeJointsFromKeypoints(label.mesh.keypoints),
              testing::MatrixNear(label.mesh.joints, 1e-12));
}

TEST(LabelRecord, BadJsonNamesTheField) {
  nlohmann::json j = LabelToJson(MakeLabel());
  j["mano"]["hand_pose"] = {1, 2, 3};
  try {
    LabelFromJson(j, "x.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_THAT(e.what(), HasSubstr("x.json"));
    EXPECT_THAT(e.what(), HasSubstr("mano.hand_pose"));
    EXPECT_THAT(e.what(), HasSubstr("45 numbers"));
  }
}

TEST(LabelRecord, UnknownHandSideIsRefused) {
  nlohmann::json j = LabelToJson(MakeLabel());
  EXPECT_EQ(j["hand_side"], "right");
  j["hand_side"] = "left";
  EXPECT_EQ(LabelFromJson(j, "x.json").side, HandSide::kLeft);
  j["hand_side"] = "Left";  // was read as a right hand
  const std::string error = testing::InputErrorOf([&] { LabelFromJson(j, "x.json"); });
  EXPECT_THAT(error, HasSubstr("x.json"));
  EXPECT_THAT(error, HasSubstr("hand_side"));
}

TEST(LabelRecord, FrameIdsBecomeSafeFileNames) {
  EXPECT_EQ(FrameFileStem("20200709-subject-01/20200709_141754/000012", "x"),
            "20200709-subject-01__20200709_141754__000012");
  EXPECT_THROW(FrameFileStem("../etc", "x"), InputError);
  EXPECT_THROW(FrameFileStem("a b", "x"), InputError);
  EXPECT_THROW(FrameFileStem("", "x"), InputError);
}

TEST(LabelRecord, MeshFilesReadBackWithOpenMesh) {
  const LabelRecord label = MakeLabel();
  // A fan over all vertices: every face is known (face 3 is 0, 4, 5).
  Faces faces(label.mesh.vertices.rows() - 2, 3);
  for (int f = 0; f < faces.rows(); ++f) faces.row(f) << 0, f + 1, f + 2;
  const std::string out = testing::ScratchDir();
  WriteLabelFiles(out, label, faces, {"ply", "obj"});
  EXPECT_TRUE(fs::exists(LabelFilePath(out, label.frame)));
  for (const char* ext : {"ply", "obj"}) {
    OpenMesh::TriMesh_ArrayKernelT<> mesh;
    ASSERT_TRUE(OpenMesh::IO::read_mesh(mesh, MeshFilePath(out, label.frame, ext)))
        << ext;
    ASSERT_EQ(int(mesh.n_vertices()), label.mesh.vertices.rows()) << ext;
    ASSERT_EQ(int(mesh.n_faces()), faces.rows()) << ext;
    for (int v = 0; v < label.mesh.vertices.rows(); ++v) {
      const auto p = mesh.point(OpenMesh::VertexHandle(v));
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(p[c], label.mesh.vertices(v, c), 1e-6);
    }
    const auto face = mesh.face_handle(3);
    std::vector<int> ids;
    for (auto fv = mesh.cfv_iter(face); fv.is_valid(); ++fv) ids.push_back(fv->idx());
    EXPECT_THAT(ids, ::testing::UnorderedElementsAre(0, 4, 5)) << ext;
  }
}

}  // namespace
}  // namespace handlabel
