#include "hand/hand_evaluator.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "geometry/dual.h"
#include "hand/hand_lbs.h"
#include "hand/hand_params_json.h"
#include "tests/hand/lbs_fixture.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::JsonHandParams;
using testing::JsonVector;
using testing::MatrixNear;

constexpr int kNumParams = 3 + 45 + 10 + 3;  // orient, pose, betas, transl
using D = Dual<kNumParams>;
using RowPoints = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;

Eigen::VectorXd Pack(const HandParams& p) {
  Eigen::VectorXd x(kNumParams);
  x << p.global_orient, p.hand_pose, p.betas, p.transl;
  return x;
}

// Evaluates keypoints (first 63) and all vertices (rest) of x in doubles.
Eigen::VectorXd EvalAll(const HandEvaluator& ev, const Eigen::VectorXd& x) {
  Eigen::VectorXd out(63 + 3 * ev.num_vertices());
  HandPoseState<double> state;
  ev.Pose(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, &state);
  ev.KeypointsFromState(state, out.data());
  ev.AllVerticesFromState(state, out.data() + 63);
  return out;
}

TEST(AxisAngleToRotation, MatchesEigenIncludingTinyAndZeroAngles) {
  for (double scale : {0.0, 1e-12, 1e-5, 1e-3, 0.5, 3.0}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d w = scale * testing::RandomVector3(-1, 1);
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor> r;
      AxisAngleToRotation(w.data(), r.data());
      const Eigen::Matrix3d expected =
          w.norm() == 0 ? Eigen::Matrix3d::Identity()
                        : Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
      EXPECT_THAT(r, MatrixNear(expected, 1e-15)) << "scale " << scale;
    }
  }
}

TEST(AxisAngleToRotation, DualDerivativesMatchFiniteDifferencesAtAndNearZero) {
  for (double scale : {0.0, 1e-5, 0.3, 2.0}) {
    const Eigen::Vector3d w = scale * testing::RandomVector3(-1, 1);
    Dual<3> wd[3] = {Dual<3>(w[0], 0), Dual<3>(w[1], 1), Dual<3>(w[2], 2)};
    Dual<3> rd[9];
    AxisAngleToRotation(wd, rd);
    for (int k = 0; k < 3; ++k) {
      const double h = 1e-6;
      Eigen::Vector3d wp = w, wm = w;
      wp[k] += h;
      wm[k] -= h;
      double rp[9], rm[9];
      AxisAngleToRotation(wp.data(), rp);
      AxisAngleToRotation(wm.data(), rm);
      for (int i = 0; i < 9; ++i) {
        EXPECT_NEAR(rd[i].v[k], (rp[i] - rm[i]) / (2 * h), 1e-8)
            << "scale " << scale << " entry " << i << " param " << k;
      }
    }
  }
}

TEST(HandEvaluator, DoublesMatchPoseHand) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  const HandEvaluator ev(model);
  for (const nlohmann::json& c : fixture["cases"]) {
    SCOPED_TRACE(c["name"].get<std::string>());
    const HandParams p = JsonHandParams(c);
    const HandMesh mesh = PoseHand(model, p);
    const Eigen::VectorXd x = Pack(p);
    RowPoints keypoints(21, 3), joints(16, 3), vertices(model.num_vertices(), 3);
    ev.Keypoints(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, keypoints.data());
    ev.Joints(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, joints.data());
    ev.AllVertices(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, vertices.data());
    EXPECT_THAT(keypoints, MatrixNear(mesh.keypoints, 1e-12));
    EXPECT_THAT(joints, MatrixNear(mesh.joints, 1e-12));
    EXPECT_THAT(vertices, MatrixNear(mesh.vertices, 1e-12));
    const std::vector<int> ids = {7, 3, 3, 40};
    RowPoints subset(4, 3);
    ev.Vertices(x.data(), x.data() + 3, x.data() + 48, x.data() + 58, ids, subset.data());
    for (int i = 0; i < 4; ++i) {
      EXPECT_THAT(subset.row(i), MatrixNear(mesh.vertices.row(ids[i]), 1e-12));
    }
  }
}

TEST(HandEvaluator, NullBetasAndTranslMeanZeros) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  const HandEvaluator ev(model);
  HandParams p = JsonHandParams(fixture["cases"][3]);
  p.betas.setZero();
  p.transl.setZero();
  RowPoints keypoints(21, 3);
  ev.Keypoints(p.global_orient.data(), p.hand_pose.data(), static_cast<double*>(nullptr),
               static_cast<double*>(nullptr), keypoints.data());
  EXPECT_THAT(keypoints, MatrixNear(PoseHand(model, p).keypoints, 1e-12));
}

TEST(HandEvaluator, PcaModeMatchesPoseHandWithHandPoseFromPca) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  for (const nlohmann::json& c : fixture["pca_cases"]) {
    const Eigen::VectorXd coeffs = JsonVector(c["coeffs"]);
    HandEvaluatorOptions options;
    options.num_pca_comps = static_cast<int>(coeffs.size());
    options.flat_hand_mean = c["flat_hand_mean"].get<bool>();
    const HandEvaluator ev(model, options);
    ASSERT_EQ(ev.pose_dim(), coeffs.size());
    const HandParams p = JsonHandParams(c);  // hand_pose = NumPy's PCA expansion
    RowPoints vertices(model.num_vertices(), 3), keypoints(21, 3);
    ev.AllVertices(p.global_orient.data(), coeffs.data(), p.betas.data(), p.transl.data(),
                   vertices.data());
    ev.Keypoints(p.global_orient.data(), coeffs.data(), p.betas.data(), p.transl.data(),
                 keypoints.data());
    EXPECT_THAT(vertices, MatrixNear(testing::JsonMatrix(c["vertices"]), 1e-9));
    EXPECT_THAT(keypoints, MatrixNear(PoseHand(model, p).keypoints, 1e-9));
  }
}

TEST(HandEvaluator, RejectsOptionsThatDoNotFitTheModel) {
  const HandModel model = testing::LbsFixtureModel(testing::LoadLbsFixtureJson());
  HandEvaluatorOptions options;
  options.num_betas = model.num_betas() + 1;
  EXPECT_THROW(HandEvaluator(model, options), InputError);
  options = {};
  options.num_pca_comps = 46;
  EXPECT_THROW(HandEvaluator(model, options), InputError);
  options = {};
  options.num_betas = -2;
  EXPECT_THROW(options.Check("test"), InputError);
  options = {};
  options.num_pca_comps = -1;
  EXPECT_THROW(options.Check("test"), InputError);
  EXPECT_NO_THROW(HandEvaluatorOptions().Check("test"));
}

// Dual derivatives of keypoints and all vertices w.r.t. all 61 parameters versus
// central differences, at a generic pose and at the zero pose (Taylor branch).
TEST(HandEvaluator, DualJacobianMatchesCentralDifferences) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  const HandEvaluator ev(model);
  for (int case_index : {0, 3, 4}) {
    SCOPED_TRACE(fixture["cases"][case_index]["name"].get<std::string>());
    const Eigen::VectorXd x = Pack(JsonHandParams(fixture["cases"][case_index]));
    std::vector<D> xd(kNumParams);
    for (int k = 0; k < kNumParams; ++k) xd[k] = D(x[k], k);
    const int num_out = 63 + 3 * model.num_vertices();
    std::vector<D> out(num_out);
    HandPoseState<D> state;
    ev.Pose(xd.data(), xd.data() + 3, xd.data() + 48, xd.data() + 58, &state);
    ev.KeypointsFromState(state, out.data());
    ev.AllVerticesFromState(state, out.data() + 63);
    const Eigen::VectorXd value = EvalAll(ev, x);
    Eigen::MatrixXd jac(num_out, kNumParams), numeric(num_out, kNumParams);
    for (int i = 0; i < num_out; ++i) {
      ASSERT_NEAR(out[i].a, value[i], 1e-14);
      jac.row(i) = out[i].v.transpose();
    }
    const double h = 1e-6;
    for (int k = 0; k < kNumParams; ++k) {
      Eigen::VectorXd xp = x, xm = x;
      xp[k] += h;
      xm[k] -= h;
      numeric.col(k) = (EvalAll(ev, xp) - EvalAll(ev, xm)) / (2 * h);
    }
    EXPECT_THAT(jac, MatrixNear(numeric, 1e-7));
    EXPECT_GT(jac.cwiseAbs().maxCoeff(), 0.1);  // not trivially zero
  }
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

// The analytic keypoints and Jacobian (axis-angle and PCA modes) at fixed random
// parameters: the same bits when computed twice, and the values of
// tests/data/reference/hand_evaluator_keypoint_jacobian.txt within 1e-12 m (+ 1e-9
// relative). The skinning goes through libm's sin/cos, whose FMA and plain variants
// differ by about 1e-16 relative; a changed formula moves the values by far more.
testing::ReferenceValues KeypointJacobianValues() {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  testing::ReferenceValues values("hand_evaluator_keypoint_jacobian");
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> uniform(-0.6, 0.6);
  for (int pca : {0, 7}) {
    HandEvaluatorOptions options;
    options.num_pca_comps = pca;
    const HandEvaluator ev(model, options);
    const int np = ev.num_params(), pd = ev.pose_dim();
    for (int trial = 0; trial < 3; ++trial) {
      Eigen::VectorXd x(np);
      for (int i = 0; i < np; ++i) x[i] = uniform(rng);
      Eigen::Matrix<double, 63, Eigen::Dynamic, Eigen::RowMajor> jac(63, np);
      Eigen::Matrix<double, 63, 1> keypoints;
      ev.KeypointsAndJacobian(x.data(), x.data() + 3, x.data() + 3 + pd,
                              x.data() + 3 + pd + 10, keypoints.data(), jac.data());
      const std::string at =
          "pca" + std::to_string(pca) + ".trial" + std::to_string(trial);
      values.Near(at + ".keypoints", keypoints).Near(at + ".jacobian", jac);
    }
  }
  return values;
}

TEST(HandEvaluator, AnalyticKeypointJacobianKeepsItsValues) {
  const testing::ReferenceValues first = KeypointJacobianValues();
  EXPECT_EQ(first.Bits(), KeypointJacobianValues().Bits());
  EXPECT_TRUE(first.Compare(1e-12, 1e-9));
}

// Analytic keypoint Jacobian against Dual forward mode, axis-angle and PCA modes.
TEST(HandEvaluator, AnalyticKeypointJacobianMatchesDuals) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  for (int pca : {0, 7}) {
    HandEvaluatorOptions options;
    options.num_pca_comps = pca;
    const HandEvaluator ev(model, options);
    const int np = ev.num_params();
    ASSERT_EQ(np, 3 + (pca ? pca : 45) + 10 + 3);
    for (int case_index : {0, 3, 4}) {
      const nlohmann::json& c = fixture["cases"][case_index];
      Eigen::VectorXd pca_coeffs(pca);
      for (int i = 0; i < pca; ++i) pca_coeffs[i] = testing::Uniform(-0.5, 0.5);
      Eigen::VectorXd x(np);
      x << JsonVector(c["global_orient"]), pca ? pca_coeffs : JsonVector(c["hand_pose"]),
          JsonVector(c["betas"]), JsonVector(c["transl"]);
      using D = Dual<kNumParams>;
      std::vector<D> xd(np);
      for (int k = 0; k < np; ++k) xd[k] = D(x[k], k);
      std::vector<D> expected(63);
      const int pd = ev.pose_dim();
      ev.Keypoints(xd.data(), xd.data() + 3, xd.data() + 3 + pd, xd.data() + 3 + pd + 10,
                   expected.data());
      Eigen::Matrix<double, 63, Eigen::Dynamic, Eigen::RowMajor> jac(63, np);
      Eigen::Matrix<double, 63, 1> keypoints;
      ev.KeypointsAndJacobian(x.data(), x.data() + 3, x.data() + 3 + pd,
                              x.data() + 3 + pd + 10, keypoints.data(), jac.data());
      Eigen::MatrixXd expected_jac(63, np);
      Eigen::VectorXd expected_kp(63);
      for (int i = 0; i < 63; ++i) {
        expected_kp[i] = expected[i].a;
        expected_jac.row(i) = expected[i].v.head(np).transpose();
      }
      EXPECT_THAT(keypoints, MatrixNear(expected_kp, 1e-12)) << "pca " << pca;
      EXPECT_THAT(jac, MatrixNear(expected_jac, 1e-10)) << "pca " << pca;

      // Vertices (any ids, repeats allowed) the same way.
      const std::vector<int> ids = {0, ev.num_vertices() - 1, ev.num_vertices() / 2, 0};
      const int nr = 3 * static_cast<int>(ids.size());
      std::vector<D> expected_v(nr);
      ev.Vertices(xd.data(), xd.data() + 3, xd.data() + 3 + pd, xd.data() + 3 + pd + 10,
                  ids, expected_v.data());
      Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> vjac(nr, np);
      Eigen::VectorXd vertices(nr), expected_vertices(nr);
      ev.VerticesAndJacobian(x.data(), x.data() + 3, x.data() + 3 + pd,
                             x.data() + 3 + pd + 10, ids, vertices.data(), vjac.data());
      Eigen::MatrixXd expected_vjac(nr, np);
      for (int i = 0; i < nr; ++i) {
        expected_vertices[i] = expected_v[i].a;
        expected_vjac.row(i) = expected_v[i].v.head(np).transpose();
      }
      EXPECT_THAT(vertices, MatrixNear(expected_vertices, 1e-12)) << "pca " << pca;
      EXPECT_THAT(Eigen::MatrixXd(vjac), MatrixNear(expected_vjac, 1e-10))
          << "pca " << pca;
    }
  }
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

TEST(HandEvaluator, FewerBetasThanTheModelUseTheLeadingOnes) {
  const nlohmann::json fixture = testing::LoadLbsFixtureJson();
  const HandModel model = testing::LbsFixtureModel(fixture);
  HandEvaluatorOptions options;
  options.num_betas = 4;
  const HandEvaluator ev(model, options);
  ASSERT_EQ(ev.num_betas(), 4);
  HandParams p = JsonHandParams(fixture["cases"][3]);
  p.betas = p.betas.head(4).eval();
  const HandMesh mesh = PoseHand(model, p);
  RowPoints vertices(model.num_vertices(), 3);
  ev.AllVertices(p.global_orient.data(), p.hand_pose.data(), p.betas.data(),
                 p.transl.data(), vertices.data());
  EXPECT_THAT(vertices, MatrixNear(mesh.vertices, 1e-12));
  // Dual path too (it evaluates the blend shapes differently).
  std::vector<Dual<4>> betas(4);
  for (int s = 0; s < 4; ++s) betas[s] = Dual<4>(p.betas[s], s);
  std::vector<Dual<4>> orient(p.global_orient.data(), p.global_orient.data() + 3);
  std::vector<Dual<4>> pose(p.hand_pose.data(), p.hand_pose.data() + 45);
  std::vector<Dual<4>> keypoints(63);
  ev.Keypoints(orient.data(), pose.data(), betas.data(), static_cast<Dual<4>*>(nullptr),
               keypoints.data());
  const HandMesh no_transl = [&] {
    HandParams q = p;
    q.transl.setZero();
    return PoseHand(model, q);
  }();
  for (int k = 0; k < 21; ++k) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(keypoints[3 * k + c].a, no_transl.keypoints(k, c), 1e-12);
    }
  }
}

}  // namespace
}  // namespace handlabel
