#include "core/mesh_keypoints.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/core/lbs_fixture.h"
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

}  // namespace
}  // namespace handlabel
