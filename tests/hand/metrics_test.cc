#include "hand/metrics.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/errors.h"
#include "tests/hand/lbs_fixture.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::JsonMatrix;

Points3d Pts(std::initializer_list<std::array<double, 3>> rows) {
  Points3d p(rows.size(), 3);
  int i = 0;
  for (const auto& r : rows) p.row(i++) << r[0], r[1], r[2];
  return p;
}

TEST(MetricsTest, HandComputedMeanErrors) {
  const Points3d truth = Pts({{0, 0, 0}, {1, 0, 0}, {0, 1, 0}});
  const Points3d pred = Pts({{0, 0, 3}, {1, 4, 0}, {0, 1, 0}});
  // Distances 3, 4, 0.
  EXPECT_DOUBLE_EQ(MeanPointError(pred, truth), 7.0 / 3.0);
  // Root-relative: pred - (0,0,3) = {0,0,0}, {1,4,-3}, {0,1,-3}; distances 0, 5, 3.
  EXPECT_DOUBLE_EQ(RootRelativeMeanPointError(pred, truth, pred.row(0).transpose(),
                                              truth.row(0).transpose()),
                   8.0 / 3.0);
}

TEST(MetricsTest, ProcrustesUndoesASimilarity) {
  Points3d truth(21, 3);
  for (int i = 0; i < 21; ++i) truth.row(i) = testing::RandomVector3(-0.05, 0.05);
  const Eigen::Matrix3d r = testing::RandomRotation().toRotationMatrix();
  SimilarityTransform s;
  s.scale = 1.3;
  s.rotation = r;
  s.translation = {0.1, -0.2, 0.7};
  const Points3d pred = s.Apply(truth);
  EXPECT_GT(MeanPointError(pred, truth), 0.01);
  EXPECT_LT(ProcrustesMeanPointError(pred, truth), 1e-12);
  const SimilarityTransform back = ProcrustesAlignment(pred, truth);
  EXPECT_NEAR(back.scale, 1.0 / 1.3, 1e-12);
  EXPECT_THAT(Eigen::MatrixXd(back.rotation), testing::MatrixNear(r.transpose(), 1e-12));
}

TEST(MetricsTest, ReflectionOnlyWhenAllowed) {
  Points3d truth(10, 3);
  for (int i = 0; i < 10; ++i) truth.row(i) = testing::RandomVector3(-1, 1);
  Points3d mirrored = truth;
  mirrored.col(0) *= -1.0;
  EXPECT_LT(ProcrustesMeanPointError(mirrored, truth, true), 1e-12);
  EXPECT_GT(ProcrustesMeanPointError(mirrored, truth, false), 0.1);
  const SimilarityTransform s = ProcrustesAlignment(mirrored, truth, false);
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
}

TEST(MetricsTest, PckHandComputed) {
  // Two frames, two points: errors {0, 1} and {2, 3}.
  Eigen::MatrixXd errors(2, 2);
  errors << 0, 2, 1, 3;
  EXPECT_DOUBLE_EQ(PckAt(errors, 0.5), 0.25);  // point 0: 1/2, point 1: 0/2
  EXPECT_DOUBLE_EQ(PckAt(errors, 2.0), 0.75);  // 2/2 and 1/2
  PckOptions o;
  o.min_threshold = 0.0;
  o.max_threshold = 4.0;
  o.steps = 5;  // thresholds 0, 1, 2, 3, 4 -> pck .25 .5 .75 1 1
  const PckCurve c = ComputePck(errors, o);
  ASSERT_EQ(c.pck.size(), 5u);
  EXPECT_DOUBLE_EQ(c.pck[1], 0.5);
  // Trapezoids: .375 + .625 + .875 + 1 = 2.875, / 4.
  EXPECT_DOUBLE_EQ(c.auc, 2.875 / 4.0);
}

TEST(MetricsTest, PckOptionsCheck) {
  PckOptions o;
  o.steps = 1;
  EXPECT_THROW(o.Check("test"), InputError);
  o = {};
  o.max_threshold = 0.0;
  EXPECT_THROW(o.Check("test"), InputError);
}

// Against NumPy/SciPy (tests/data/metrics/make_metrics_fixture.py, POEM's code path).
TEST(MetricsTest, MatchesNumpyScipyFixture) {
  std::ifstream in(std::string(HANDLABEL_SOURCE_DIR) +
                   "/tests/data/metrics/metrics_fixture.json");
  ASSERT_TRUE(in);
  const nlohmann::json fixture = nlohmann::json::parse(in);
  for (const auto& f : fixture["frames"]) {
    const Points3d truth = JsonMatrix(f["truth"]);
    const Points3d pred = JsonMatrix(f["pred"]);
    EXPECT_NEAR(MeanPointError(pred, truth), f["mean_error"].get<double>(), 1e-12);
    EXPECT_NEAR(RootRelativeMeanPointError(pred, truth, pred.row(0).transpose(),
                                           truth.row(0).transpose()),
                f["root_relative_error"].get<double>(), 1e-12);
    EXPECT_NEAR(ProcrustesMeanPointError(pred, truth), f["pa_error"].get<double>(),
                1e-10);
  }
  const auto& p = fixture["pck"];
  PckOptions o;
  o.min_threshold = p["min"];
  o.max_threshold = p["max"];
  o.steps = p["steps"];
  const Eigen::MatrixXd errors = JsonMatrix(p["errors"]);
  const PckCurve c = ComputePck(errors, o);
  for (int i = 0; i < o.steps; ++i)
    EXPECT_NEAR(c.pck[i], p["curve"][i].get<double>(), 1e-12);
  EXPECT_NEAR(c.auc, p["auc"].get<double>(), 1e-12);
  EXPECT_NEAR(PckAt(errors, 0.01), p["pck_at_10mm"].get<double>(), 1e-12);
}

TEST(MetricsTest, EvaluateHandFrameConsistent) {
  Points3d kp(21, 3), verts(40, 3);
  for (int i = 0; i < 21; ++i) kp.row(i) = testing::RandomVector3(-0.05, 0.05);
  for (int i = 0; i < 40; ++i) verts.row(i) = testing::RandomVector3(-0.05, 0.05);
  const Eigen::RowVector3d shift(0.002, 0, 0);
  const HandFrameMetrics m =
      EvaluateHandFrame(kp.rowwise() + shift, kp, verts.rowwise() + shift, verts);
  EXPECT_NEAR(m.mpjpe, 0.002, 1e-15);
  EXPECT_NEAR(m.mpvpe, 0.002, 1e-15);
  EXPECT_NEAR(m.rr_mpjpe, 0.0, 1e-15);
  EXPECT_NEAR(m.rr_mpvpe, 0.0, 1e-15);
  EXPECT_NEAR(m.pa_mpjpe, 0.0, 1e-12);
}

}  // namespace
}  // namespace handlabel
