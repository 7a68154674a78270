#include "hand/mesh_keypoints.h"
#include "hand/hand_params_json.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "hand/hand_model_io.h"
#include "tests/hand/lbs_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::MatrixNear;

// At zero pose the mesh is the shaped rest mesh, and the rest joints are by definition
// the regressor applied to it: both ways of reading keypoints must agree exactly.
TEST(KeypointsFromMeshVertices, EqualSkinnedKeypointsAtRestPose) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  HandParams params = testing::JsonHandParams(fixture["cases"][2]);
  ASSERT_GT(params.betas.norm(), 0);  // a shaped hand, not the template
  params.global_orient.setZero();
  params.hand_pose.setZero();
  params.transl.setZero();
  const HandMesh mesh = PoseHand(model, params);
  EXPECT_THAT(KeypointsFromMeshVertices(model, mesh.vertices),
              MatrixNear(mesh.keypoints, 1e-12));
}

// Posed: the fingertips are the same vertices either way; the regressed joints stay
// near the skinned ones but are not them (the regressor is fitted at rest only).
TEST(KeypointsFromMeshVertices, PosedTipsExactJointsNear) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  const HandParams params = testing::JsonHandParams(fixture["cases"][2]);
  ASSERT_GT(params.hand_pose.norm(), 0.1);
  const HandMesh mesh = PoseHand(model, params);
  const Points3d keypoints = KeypointsFromMeshVertices(model, mesh.vertices);
  double joint_gap = 0;
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    const int native = kSnapFromNative[k];
    const double gap = (keypoints.row(k) - mesh.keypoints.row(k)).norm();
    if (native >= kNumHandJoints) {
      EXPECT_EQ(gap, 0) << "tip " << k;
    } else {
      joint_gap = std::max(joint_gap, gap);
    }
  }
  const double span =
      (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
  EXPECT_GT(joint_gap, 0);
  EXPECT_LT(joint_gap, 0.5 * span);
}

TEST(KeypointsFromMeshVertices, RejectsWrongVertexCount) {
  const HandModel model = testing::LbsFixtureModel(testing::LoadLbsFixtureJson());
  EXPECT_THROW(
      KeypointsFromMeshVertices(model, Points3d::Zero(model.num_vertices() - 1, 3)),
      InputError);
}

// A network's answer: a posed mesh of the shipped open hand, and "joints" that are its
// skinned keypoints moved off by a known offset (a second, disagreeing estimate).
struct Answer {
  HandModel model;
  Points3d joints, vertices;
};
Answer MakeAnswer() {
  Answer a;
  a.model =
      LoadHandModel(std::string(HANDLABEL_SOURCE_DIR) + "/models/open_hand_right.npz");
  HandParams params;
  params.hand_pose.setConstant(0.15);
  params.global_orient = Eigen::Vector3d(0.3, -0.2, 0.1);
  params.transl = Eigen::Vector3d(0.05, -0.02, 0.6);
  const HandMesh mesh = PoseHand(a.model, params);
  a.vertices = mesh.vertices;
  a.joints = mesh.keypoints;
  a.joints.col(0).array() += 0.004;
  return a;
}

TEST(ReadAnswerKeypoints, JointsMeshAndTheirMean) {
  const Answer a = MakeAnswer();
  const Points3d from_mesh = KeypointsFromMeshVertices(a.model, a.vertices);
  EXPECT_EQ(ReadAnswerKeypoints(a.model, a.joints, a.vertices, AnswerKeypoints::kJoints),
            a.joints);
  EXPECT_EQ(ReadAnswerKeypoints(a.model, a.joints, a.vertices, AnswerKeypoints::kMesh),
            from_mesh);
  const Points3d mean =
      ReadAnswerKeypoints(a.model, a.joints, a.vertices, AnswerKeypoints::kMean);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    // Equidistant from both readings, half their gap from each.
    const double gap = (a.joints.row(k) - from_mesh.row(k)).norm();
    EXPECT_NEAR((mean.row(k) - a.joints.row(k)).norm(), gap / 2, 1e-12) << k;
    EXPECT_NEAR((mean.row(k) - from_mesh.row(k)).norm(), gap / 2, 1e-12) << k;
  }
}

// The job reads answers in the world frame, eval-network in the master camera's: the
// readings must commute with a rigid motion (the regressor's rows sum to one).
TEST(ReadAnswerKeypoints, CommutesWithARigidMotion) {
  const Answer a = MakeAnswer();
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::RowVector3d t(0.4, -1.3, 2.2);
  auto move = [&](const Points3d& p) -> Points3d {
    return (p * R.transpose()).rowwise() + t;
  };
  for (AnswerKeypoints how : {AnswerKeypoints::kMesh, AnswerKeypoints::kMean}) {
    EXPECT_THAT(
        ReadAnswerKeypoints(a.model, move(a.joints), move(a.vertices), how),
        MatrixNear(move(ReadAnswerKeypoints(a.model, a.joints, a.vertices, how)), 1e-9))
        << ToString(how);
  }
}

TEST(ReadAnswerKeypoints, NamesRoundTripAndUnknownNamesAreRefused) {
  for (AnswerKeypoints how :
       {AnswerKeypoints::kJoints, AnswerKeypoints::kMesh, AnswerKeypoints::kMean}) {
    EXPECT_EQ(AnswerKeypointsNamed(ToString(how)), how);
  }
  EXPECT_EQ(AnswerKeypointsChoices(), "joints | mesh | mean");
  EXPECT_FALSE(AnswerKeypointsNamed("median").has_value());
  EXPECT_FALSE(AnswerKeypointsNamed("").has_value());
}

}  // namespace
}  // namespace handlabel
