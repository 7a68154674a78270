// The open hand builder: geometry, skinning, regressor, conventions, mirror,
// determinism. Uses a coarse build (seconds); the shipped models are checked in
// open_hand_model_test.cc.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/hand_anatomy.h"
#include "core/hand_lbs.h"
#include "openhand/builder.h"
#include "openhand/mesh_checks.h"
#include "openhand/shape_space.h"
#include "tests/openhand/open_hand_checks.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

OpenHandBuildOptions CoarseOptions() {
  OpenHandBuildOptions o;
  o.grid_step = 0.004;
  o.relax_iterations = 3;
  o.num_shape_samples = 40;
  o.num_pose_samples = 200;
  return o;
}

const HandModel& CoarseRight() {
  static const HandModel model = BuildOpenHand(DefaultOpenHandDesign(), CoarseOptions());
  return model;
}

TEST(OpenHandBuilder, CoarseModelPassesTheModelChecks) {
  testing::ExpectPlausibleOpenHand(CoarseRight());
}

TEST(OpenHandBuilder, RegressorReproducesDesignJointsOfSampledShapes) {
  // Deform the template to random designs (the builder's shape construction) and
  // regress: the joints must be the designs' joints.
  const HandModel& model = CoarseRight();
  const OpenHandDesign design = DefaultOpenHandDesign();
  std::vector<Eigen::Vector3d> vertices(model.num_vertices());
  for (int v = 0; v < model.num_vertices(); ++v) vertices[v] = model.v_template.row(v);
  std::mt19937_64 rng(testing::TestSeed());
  double worst = 0.0;
  for (int s = 0; s < 10; ++s) {
    const OpenHandDesign sample = SampleOpenHandDesign(design, OpenHandVariation(), rng);
    const auto deformed =
        DeformToDesign(vertices, model.skinning_weights, design, sample);
    Points3d p(model.num_vertices(), 3);
    for (int v = 0; v < model.num_vertices(); ++v) p.row(v) = deformed[v];
    const Points3d joints = model.joint_regressor * p;
    const OpenHandSkeleton sk = SkeletonFromDesign(sample);
    for (int j = 0; j < kNumHandJoints; ++j)
      worst = std::max(worst, (joints.row(j).transpose() - sk.joints[j]).norm());
  }
  // Outside the 10-component span the fit is not exact; sub-millimetre is the bar.
  EXPECT_LT(worst, 1e-3);
}

TEST(OpenHandBuilder, ShapeSpaceIsOrderedAndNearlyOrthogonal) {
  const HandModel& model = CoarseRight();
  ASSERT_EQ(model.num_betas(), 10);
  const Eigen::MatrixXd& s = model.shapedirs;
  for (int k = 0; k + 1 < 10; ++k) EXPECT_GE(s.col(k).norm(), s.col(k + 1).norm());
  for (int a = 0; a < 10; ++a) {
    for (int b = a + 1; b < 10; ++b) {
      const double c = s.col(a).dot(s.col(b)) / (s.col(a).norm() * s.col(b).norm());
      EXPECT_LT(std::abs(c), 0.05) << a << " " << b;  // only the 48 joint rows differ
    }
  }
  // Beta 0 (the largest) is overall size: +1 makes the hand longer.
  HandParams p;
  p.betas = Eigen::VectorXd::Zero(10);
  const double rest =
      (PoseHand(model, p).keypoints.row(0) - PoseHand(model, p).keypoints.row(12)).norm();
  p.betas[0] = 1.0;
  const HandMesh big = PoseHand(model, p);
  EXPECT_GT((big.keypoints.row(0) - big.keypoints.row(12)).norm(), rest + 0.003);
}

TEST(OpenHandBuilder, SameSeedSameModelDifferentSeedDifferentShapes) {
  const HandModel again = BuildOpenHand(DefaultOpenHandDesign(), CoarseOptions());
  const HandModel& first = CoarseRight();
  EXPECT_TRUE(again.v_template == first.v_template);
  EXPECT_TRUE(again.faces == first.faces);
  EXPECT_TRUE(again.shapedirs == first.shapedirs);
  EXPECT_TRUE(again.skinning_weights == first.skinning_weights);
  EXPECT_TRUE(Eigen::MatrixXd(again.joint_regressor) ==
              Eigen::MatrixXd(first.joint_regressor));
  EXPECT_TRUE(again.pose_pca_basis == first.pose_pca_basis);
  EXPECT_TRUE(again.pose_mean == first.pose_mean);
  EXPECT_EQ(again.tip_vertex_ids, first.tip_vertex_ids);
}

// The coarse model (surface, skinning, shapes, regressor, tips, pose PCA) and the build
// report against tests/data/reference/open_hand_coarse_build.txt: topology and indices
// exactly, values within 1e-9 relative to each array's scale. The pose PCA comes from
// poses sampled through libm's sin/cos, and the shape and pose spaces from LAPACK-style
// eigen solvers, whose last bits differ between CPUs (8e-14 in the pose basis between
// glibc's FMA and plain variants). Determinism on one machine is
// SameSeedSameModelDifferentSeedDifferentShapes above.
TEST(OpenHandBuilder, CoarseBuildKeepsItsValues) {
  OpenHandBuildReport report;
  const HandModel m = BuildOpenHand(DefaultOpenHandDesign(), CoarseOptions(), &report);
  testing::ReferenceValues values("open_hand_coarse_build");
  values.Exact("name", m.name).Exact("side", static_cast<int>(m.side));
  values.Near("v_template", m.v_template);
  values.Exact("faces",
               std::vector<int>(m.faces.data(), m.faces.data() + m.faces.size()));
  values.Near("shapedirs", m.shapedirs).Near("posedirs", m.posedirs);
  values.Near("skinning_weights", m.skinning_weights);
  values.Near("joint_regressor", Eigen::MatrixXd(m.joint_regressor));
  values.Near("pose_pca_basis", m.pose_pca_basis).Near("pose_mean", m.pose_mean);
  values.Exact("parents", std::vector<int>(m.parents.begin(), m.parents.end()));
  values.Exact("tip_vertex_ids",
               std::vector<int>(m.tip_vertex_ids.begin(), m.tip_vertex_ids.end()));
  values.Exact("fine_vertices", report.fine_vertices);
  values.Exact("fine_faces", report.fine_faces);
  values.Near("shape_variance_explained", report.shape_variance_explained);
  values.Near("max_regressor_error", report.max_regressor_error);
  values.Near("max_regressor_error_mean", report.max_regressor_error_mean);
  values.Near("pose_variance_explained_6", report.pose_variance_explained_6);
  EXPECT_TRUE(values.Compare(0, 1e-9));
}

TEST(OpenHandBuilder, LeftIsTheMirrorOfRight) {
  OpenHandBuildOptions o = CoarseOptions();
  o.side = HandSide::kLeft;
  const HandModel left = BuildOpenHand(DefaultOpenHandDesign(), o);
  const HandModel& right = CoarseRight();
  EXPECT_EQ(left.side, HandSide::kLeft);
  EXPECT_EQ(left.name, "open_hand_left");
  testing::ExpectMirrorPair(right, left);
  testing::ExpectPlausibleOpenHand(left);
}

TEST(OpenHandBuilder, RejectsBadOptions) {
  OpenHandBuildOptions o;
  o.grid_step = 0.0;
  EXPECT_THROW(BuildOpenHand(DefaultOpenHandDesign(), o), InputError);
  o = OpenHandBuildOptions();
  o.num_betas = 0;
  EXPECT_THROW(BuildOpenHand(DefaultOpenHandDesign(), o), InputError);
  OpenHandDesign d = DefaultOpenHandDesign();
  d.fingers[2].lengths[1] = -0.01;
  EXPECT_THROW(BuildOpenHand(d, CoarseOptions()), InputError);
}

}  // namespace
}  // namespace handlabel
