#include "hand/hand_lbs.h"

#include <gtest/gtest.h>

#include "core/errors.h"
#include "hand/hand_params_json.h"
#include "tests/hand/lbs_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::JsonHandParams;
using testing::JsonMatrix;
using testing::JsonVector;
using testing::MatrixNear;

// PoseHand against the independent NumPy implementation (make_lbs_fixture.py).
TEST(PoseHand, MatchesNumPyReference) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  ASSERT_GE(fixture["cases"].size(), 5u);
  for (const nlohmann::json& c : fixture["cases"]) {
    SCOPED_TRACE(c["name"].get<std::string>());
    const HandMesh mesh = PoseHand(model, JsonHandParams(c));
    EXPECT_THAT(mesh.vertices, MatrixNear(JsonMatrix(c["vertices"]), 1e-9));
    EXPECT_THAT(mesh.joints, MatrixNear(JsonMatrix(c["joints"]), 1e-9));
    EXPECT_THAT(mesh.keypoints, MatrixNear(JsonMatrix(c["keypoints"]), 1e-9));
  }
}

TEST(PoseHand, PcaPoseMatchesNumPyReference) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  for (const nlohmann::json& c : fixture["pca_cases"]) {
    const Eigen::VectorXd coeffs = JsonVector(c["coeffs"]);
    SCOPED_TRACE("pca comps " + std::to_string(coeffs.size()));
    HandParams params = JsonHandParams(c);
    const Eigen::VectorXd expected_pose = params.hand_pose;
    params.hand_pose = HandPoseFromPca(model, coeffs, c["flat_hand_mean"].get<bool>());
    EXPECT_THAT(params.hand_pose, MatrixNear(expected_pose, 1e-12));
    const HandMesh mesh = PoseHand(model, params);
    EXPECT_THAT(mesh.vertices, MatrixNear(JsonMatrix(c["vertices"]), 1e-9));
    EXPECT_THAT(mesh.keypoints, MatrixNear(JsonMatrix(c["keypoints"]), 1e-9));
  }
}

TEST(PoseHand, MissingBetasAreZeroAndTooManyAreRejected) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  HandParams params = JsonHandParams(fixture["cases"][2]);
  HandParams padded = params;
  params.betas = params.betas.head(4).eval();
  padded.betas.tail(padded.betas.size() - 4).setZero();
  EXPECT_THAT(PoseHand(model, params).vertices,
              MatrixNear(PoseHand(model, padded).vertices, 1e-15));
  params.betas = Eigen::VectorXd::Zero(model.num_betas() + 1);
  EXPECT_THROW(PoseHand(model, params), InputError);
  EXPECT_THROW(HandPoseFromPca(model, Eigen::VectorXd::Zero(46), false), InputError);
}

}  // namespace
}  // namespace handlabel
