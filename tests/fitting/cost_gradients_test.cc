// Every cost functor's derivatives against central finite differences, and the
// analytic keypoint Jacobian against autodiff.

#include <ceres/manifold_test_utils.h>
#include <gtest/gtest.h>

#include <memory>
#include <utility>

#include "fitting/axis_angle_manifold.h"
#include "fitting/joint_limit_cost.h"
#include "fitting/keypoint_reprojection_cost.h"
#include "fitting/points3d_cost.h"
#include "fitting/prior_costs.h"
#include "fitting/silhouette_cost.h"
#include "hand/hand_anatomy.h"
#include "tests/fitting/fitting_scene.h"
#include "tests/hand/stick_hand.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

struct Params {
  double orient[3], pose[45], betas[10], transl[3];
  std::vector<const double*> Blocks() const { return {orient, pose, betas, transl}; }
};

Params FromHandParams(const HandParams& p) {
  Params out;
  for (int i = 0; i < 3; ++i) {
    out.orient[i] = p.global_orient[i];
    out.transl[i] = p.transl[i];
  }
  for (int i = 0; i < 45; ++i) out.pose[i] = p.hand_pose[i];
  for (int i = 0; i < 10; ++i) out.betas[i] = p.betas[i];
  return out;
}

// Two implementations of one cost (e.g. autodiff and analytic) agree on residuals
// (1e-9) and on every Jacobian block (`jacobian_tolerance` relative to the block's
// largest entry).
void ExpectSameResidualsAndJacobians(const ceres::CostFunction& a,
                                     const ceres::CostFunction& b,
                                     const std::vector<const double*>& blocks,
                                     double jacobian_tolerance = 1e-8) {
  const int n = a.num_residuals();
  ASSERT_EQ(b.num_residuals(), n);
  const std::vector<int32_t>& sizes = a.parameter_block_sizes();
  ASSERT_EQ(sizes, b.parameter_block_sizes());
  std::vector<Eigen::MatrixXd> ja(sizes.size()), jb(sizes.size());
  std::vector<double*> pa(sizes.size()), pb(sizes.size());
  for (size_t k = 0; k < sizes.size(); ++k) {
    ja[k].resize(sizes[k], n);  // column-major sizes x n = Ceres' row-major n x sizes
    jb[k].resize(sizes[k], n);
    pa[k] = ja[k].data();
    pb[k] = jb[k].data();
  }
  Eigen::VectorXd ra(n), rb(n);
  ASSERT_TRUE(a.Evaluate(blocks.data(), ra.data(), pa.data()));
  ASSERT_TRUE(b.Evaluate(blocks.data(), rb.data(), pb.data()));
  EXPECT_THAT(rb, testing::MatrixNear(ra, 1e-9));
  for (size_t k = 0; k < sizes.size(); ++k) {
    const double scale = std::max(1.0, ja[k].cwiseAbs().maxCoeff());
    EXPECT_THAT(jb[k], testing::MatrixNear(ja[k], jacobian_tolerance * scale))
        << "block " << k;
  }
}

// Evaluates `cost` with Jacobians: residuals and the full Jacobian (all blocks side by
// side).
void EvaluateFull(const ceres::CostFunction& cost,
                  const std::vector<const double*>& blocks, Eigen::VectorXd* residuals,
                  Eigen::MatrixXd* jacobian) {
  const int n = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  std::vector<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
      parts(sizes.size());
  std::vector<double*> pointers(sizes.size());
  int total = 0;
  for (size_t k = 0; k < sizes.size(); ++k) {
    parts[k].resize(n, sizes[k]);
    pointers[k] = parts[k].data();
    total += sizes[k];
  }
  residuals->resize(n);
  ASSERT_TRUE(cost.Evaluate(blocks.data(), residuals->data(), pointers.data()));
  jacobian->resize(n, total);
  int offset = 0;
  for (size_t k = 0; k < sizes.size(); ++k) {
    jacobian->middleCols(offset, sizes[k]) = parts[k];
    offset += sizes[k];
  }
}

// A term in square-root form (fitting/point_term_normal_equations.h) against the same
// term with one row per residual: equal cost (with and without Jacobians), gradient
// J^T r and Gauss-Newton matrix J^T J, each within `tolerance` of its largest entry.
// `r` and `j`: the rows' residuals and full Jacobian.
void ExpectSameGaussNewton(const Eigen::VectorXd& r, const Eigen::MatrixXd& j,
                           const ceres::CostFunction& square_root,
                           const std::vector<const double*>& blocks,
                           double tolerance = 1e-8) {
  Eigen::VectorXd r2;
  Eigen::MatrixXd j2;
  EvaluateFull(square_root, blocks, &r2, &j2);
  ASSERT_EQ(r2.size(), j.cols() + 1);
  EXPECT_GT(r.squaredNorm(), 0.0);
  EXPECT_NEAR(r2.squaredNorm(), r.squaredNorm(), tolerance * r.squaredNorm());
  Eigen::VectorXd cost_only(r2.size());
  ASSERT_TRUE(square_root.Evaluate(blocks.data(), cost_only.data(), nullptr));
  EXPECT_NEAR(cost_only.squaredNorm(), r.squaredNorm(), tolerance * r.squaredNorm());
  const Eigen::VectorXd gradient = j.transpose() * r;
  const Eigen::MatrixXd gauss_newton = j.transpose() * j;
  EXPECT_THAT(Eigen::VectorXd(j2.transpose() * r2),
              testing::MatrixNear(gradient, tolerance * gradient.cwiseAbs().maxCoeff()));
  EXPECT_THAT(
      Eigen::MatrixXd(j2.transpose() * j2),
      testing::MatrixNear(gauss_newton, tolerance * gauss_newton.cwiseAbs().maxCoeff()));
}

void ExpectSameGaussNewton(const ceres::CostFunction& rows,
                           const ceres::CostFunction& square_root,
                           const std::vector<const double*>& blocks,
                           double tolerance = 1e-8) {
  ASSERT_EQ(rows.parameter_block_sizes(), square_root.parameter_block_sizes());
  Eigen::VectorXd r;
  Eigen::MatrixXd j;
  EvaluateFull(rows, blocks, &r, &j);
  ExpectSameGaussNewton(r, j, square_root, blocks, tolerance);
}

// Central differences (step 1e-6) against the cost function's Jacobians, block by
// block; tolerance `precision` relative to the largest entry of the column (plus the
// same absolute amount).
void ExpectGradientsMatch(const ceres::CostFunction& cost,
                          const std::vector<const double*>& blocks, double precision) {
  const int n = cost.num_residuals();
  const std::vector<int32_t>& sizes = cost.parameter_block_sizes();
  ASSERT_EQ(sizes.size(), blocks.size());
  std::vector<std::vector<double>> values(blocks.size());
  std::vector<const double*> pointers(blocks.size());
  std::vector<std::vector<double>> jac(blocks.size());
  std::vector<double*> jac_ptr(blocks.size());
  for (size_t b = 0; b < blocks.size(); ++b) {
    values[b].assign(blocks[b], blocks[b] + sizes[b]);
    pointers[b] = values[b].data();
    jac[b].resize(static_cast<size_t>(n) * sizes[b]);
    jac_ptr[b] = jac[b].data();
  }
  std::vector<double> r0(n), plus(n), minus(n);
  ASSERT_TRUE(cost.Evaluate(pointers.data(), r0.data(), jac_ptr.data()));
  int bad = 0;
  for (size_t b = 0; b < blocks.size(); ++b) {
    for (int c = 0; c < sizes[b]; ++c) {
      const double h = 1e-6;
      const double x = values[b][c];
      values[b][c] = x + h;
      ASSERT_TRUE(cost.Evaluate(pointers.data(), plus.data(), nullptr));
      values[b][c] = x - h;
      ASSERT_TRUE(cost.Evaluate(pointers.data(), minus.data(), nullptr));
      values[b][c] = x;
      double column_scale = 1.0;
      for (int r = 0; r < n; ++r) {
        column_scale = std::max(column_scale, std::abs(jac[b][r * sizes[b] + c]));
      }
      for (int r = 0; r < n; ++r) {
        const double numeric = (plus[r] - minus[r]) / (2 * h);
        const double analytic = jac[b][r * sizes[b] + c];
        if (std::abs(numeric - analytic) > precision * column_scale && bad++ < 10) {
          ADD_FAILURE() << "block " << b << " param " << c << " residual " << r
                        << ": jacobian " << analytic << " vs finite difference "
                        << numeric;
        }
      }
    }
  }
  EXPECT_EQ(bad, 0);
}

class CostGradientsTest : public ::testing::Test {
 protected:
  CostGradientsTest()
      : model_(testing::MakeStickHand(HandSide::kRight)),
        evaluator_(model_),
        frame_(testing::RandomSceneFrame(model_, testing::TestRng())) {
    // Evaluate slightly away from the truth so residuals are non-zero.
    HandParams p = frame_.params;
    for (int i = 0; i < 45; ++i) p.hand_pose[i] += testing::Gaussian(0.05);
    p.transl += testing::RandomVector3(-0.003, 0.003);
    params_ = FromHandParams(p);
  }
  HandModel model_;
  HandEvaluator evaluator_;
  testing::SceneFrame frame_;
  Params params_;
};

TEST_F(CostGradientsTest, KeypointReprojectionAutodiff) {
  for (RobustLossType type :
       {RobustLossType::kTrivial, RobustLossType::kHuber, RobustLossType::kCauchy}) {
    std::unique_ptr<ceres::CostFunction> cost(MultiViewKeypointCost<>::Create(
        evaluator_, frame_.views, RobustLoss{type, 1.5}, 1.0));
    ExpectGradientsMatch(*cost, params_.Blocks(), 1e-6);
  }
}

TEST_F(CostGradientsTest, KeypointReprojectionAnalyticMatchesAutodiff) {
  std::vector<KeypointView> views = frame_.views;
  views[1].keypoints.confidence[3] = 0.0;  // a missing detection
  views[2].keypoints.confidence[4] = 0.3;
  for (RobustLossType type :
       {RobustLossType::kTrivial, RobustLossType::kHuber, RobustLossType::kCauchy}) {
    const RobustLoss loss{type, 1.5};
    std::unique_ptr<ceres::CostFunction> autodiff(
        MultiViewKeypointCost<>::Create(evaluator_, views, loss, 1.0));
    std::unique_ptr<ceres::CostFunction> analytic(
        MultiViewKeypointCostFunction::Create(evaluator_, views, loss, 1.0));
    ExpectSameResidualsAndJacobians(*autodiff, *analytic, params_.Blocks(), 1e-7);
    const int n = autodiff->num_residuals();
    Eigen::VectorXd ra(n);
    ASSERT_TRUE(autodiff->Evaluate(params_.Blocks().data(), ra.data(), nullptr));
    // Residual-only evaluation agrees too.
    Eigen::VectorXd rc(n);
    ASSERT_TRUE(analytic->Evaluate(params_.Blocks().data(), rc.data(), nullptr));
    EXPECT_THAT(rc, testing::MatrixNear(ra, 1e-9));
    // The square-root form the fitter uses: the same Gauss-Newton data.
    std::unique_ptr<ceres::CostFunction> square_root(
        MultiViewKeypointSquareRootCost::Create(evaluator_, views, loss, 1.0));
    ExpectSameGaussNewton(*autodiff, *square_root, params_.Blocks());
  }
}

TEST_F(CostGradientsTest, JointLimits) {
  // Push some angles beyond their limits (away from the hinge kinks).
  const HandAnatomy anatomy = ComputeHandAnatomy(model_);
  HandPoseVector angles = HandPoseVector::Zero();
  for (int i = 0; i < 45; ++i) angles[i] = testing::Uniform(-0.6, 1.2);
  const HandPoseVector pose = HandPoseFromAnatomicalAngles(anatomy, angles);
  std::unique_ptr<ceres::CostFunction> cost(
      JointLimitCost<>::Create(evaluator_, anatomy, DefaultHandLimits(), 3.0));
  Eigen::VectorXd r(45);
  const double* blocks[1] = {pose.data()};
  ASSERT_TRUE(cost->Evaluate(blocks, r.data(), nullptr));
  EXPECT_GT(r.cwiseAbs().maxCoeff(), 0.1);  // some limits are violated
  ExpectGradientsMatch(*cost, {pose.data()}, 1e-6);
}

TEST_F(CostGradientsTest, Priors) {
  Eigen::Matrix<double, 45, 1> mean, inv_sigma;
  for (int i = 0; i < 45; ++i) {
    mean[i] = testing::Gaussian(0.2);
    inv_sigma[i] = testing::Uniform(0.5, 2.0);
  }
  std::unique_ptr<ceres::CostFunction> pose(
      PosePriorCost<>::Create(evaluator_, mean, inv_sigma));
  ExpectGradientsMatch(*pose, {params_.pose}, 1e-7);
  std::unique_ptr<ceres::CostFunction> shape(ShapePriorCost<>::Create(0.7));
  ExpectGradientsMatch(*shape, {params_.betas}, 1e-7);
  const double target[3] = {0.1, 0.2, 0.3};
  std::unique_ptr<ceres::CostFunction> prior(ParameterPriorCost<3>::Create(target, 0.01));
  ExpectGradientsMatch(*prior, {params_.transl}, 1e-7);
  std::unique_ptr<ceres::CostFunction> diff(ParameterDifferenceCost<3>::Create(0.01));
  ExpectGradientsMatch(*diff, {params_.transl, target}, 1e-7);
}

// The priors folded into the keypoint term (fitting/folded_terms.h) give the
// Gauss-Newton data of the keypoint rows and the priors' rows stacked, and each prior
// still reports its own cost.
TEST_F(CostGradientsTest, PriorsFoldedIntoTheKeypointTerm) {
  const HandAnatomy anatomy = ComputeHandAnatomy(model_);
  Eigen::Matrix<double, 45, 1> mean, inv_sigma;
  for (int i = 0; i < 45; ++i) {
    mean[i] = testing::Gaussian(0.2);
    inv_sigma[i] = testing::Uniform(0.5, 2.0);
  }
  for (double& beta : params_.betas) beta = testing::Gaussian(1.0);
  const RobustLoss loss{RobustLossType::kCauchy, 1.5};
  std::vector<std::unique_ptr<ceres::CostFunction>> priors;
  priors.emplace_back(
      JointLimitCost<>::Create(evaluator_, anatomy, DefaultHandLimits(), 3.0));
  priors.emplace_back(PosePriorCost<>::Create(evaluator_, mean, inv_sigma));
  priors.emplace_back(ShapePriorCost<>::Create(0.7));
  const int prior_block[] = {1, 1, 2};
  const int block_offset[] = {0, 3, 48, 58};

  MultiViewKeypointSquareRootCost folded(evaluator_, frame_.views, loss, 1.0);
  folded.folded()->Add(
      "joint_limits",
      JointLimitCost<>::Create(evaluator_, anatomy, DefaultHandLimits(), 3.0), 1);
  folded.folded()->Add("pose_prior", PosePriorCost<>::Create(evaluator_, mean, inv_sigma),
                       1);
  folded.folded()->Add("shape_prior", ShapePriorCost<>::Create(0.7), 2);

  // The same terms as rows: the keypoints' rows, then each prior's on its block.
  std::unique_ptr<ceres::CostFunction> keypoints(
      MultiViewKeypointCost<>::Create(evaluator_, frame_.views, loss, 1.0));
  Eigen::VectorXd r;
  Eigen::MatrixXd j;
  EvaluateFull(*keypoints, params_.Blocks(), &r, &j);
  std::vector<double> prior_costs;
  for (size_t t = 0; t < priors.size(); ++t) {
    const int m = priors[t]->num_residuals();
    const int size = priors[t]->parameter_block_sizes()[0];
    Eigen::VectorXd pr(m);
    Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> pj(m, size);
    const double* block = params_.Blocks()[prior_block[t]];
    double* pj_data = pj.data();
    ASSERT_TRUE(priors[t]->Evaluate(&block, pr.data(), &pj_data));
    EXPECT_GT(pr.squaredNorm(), 0.0) << "prior " << t;
    prior_costs.push_back(0.5 * pr.squaredNorm());
    const Eigen::Index rows = r.size();
    r.conservativeResize(rows + m);
    r.tail(m) = pr;
    j.conservativeResize(rows + m, Eigen::NoChange);
    j.bottomRows(m).setZero();
    j.block(rows, block_offset[prior_block[t]], m, size) = pj;
  }
  ExpectSameGaussNewton(r, j, folded, params_.Blocks());

  const auto costs = std::as_const(folded).folded().Costs(params_.Blocks().data());
  ASSERT_EQ(costs.size(), 3u);
  for (size_t t = 0; t < costs.size(); ++t) {
    EXPECT_NEAR(costs[t].second, prior_costs[t], 1e-12 * prior_costs[t])
        << costs[t].first;
  }
}

// Every keypoint of every view undetected (a frame where the detector found no hand):
// the square-root form has no keypoint rows, as the plain cost has none: zero cost,
// zero gradient, zero Gauss-Newton matrix (it used to end the process with SIGFPE in
// Eigen's rank update of an empty matrix).
TEST_F(CostGradientsTest, KeypointTermWithoutDetectedKeypoints) {
  std::vector<KeypointView> views = frame_.views;
  for (KeypointView& v : views) v.keypoints.confidence.setZero();
  const RobustLoss loss{RobustLossType::kCauchy, 1.5};
  std::unique_ptr<ceres::CostFunction> keypoints(
      MultiViewKeypointCost<>::Create(evaluator_, views, loss, 1.0));
  Eigen::VectorXd r, r2;
  Eigen::MatrixXd j, j2;
  EvaluateFull(*keypoints, params_.Blocks(), &r, &j);
  EXPECT_EQ(r.squaredNorm(), 0.0);
  MultiViewKeypointSquareRootCost folded(evaluator_, views, loss, 1.0);
  EvaluateFull(folded, params_.Blocks(), &r2, &j2);
  EXPECT_EQ(r2.squaredNorm(), 0.0);
  // R^T R is the regulariser alone: 1e-200 on the diagonal of empty columns.
  EXPECT_LT(Eigen::MatrixXd(j2.transpose() * j2).cwiseAbs().maxCoeff(), 1e-150);
}

TEST_F(CostGradientsTest, Points3d) {
  Points3dTargets targets;
  targets.keypoints = frame_.mesh.keypoints;
  targets.keypoint_weights = Eigen::VectorXd::Ones(21);
  targets.keypoint_weights[4] = 0.0;
  targets.vertex_ids = {0, 5, 17, 20};
  targets.vertices.resize(4, 3);
  for (int i = 0; i < 4; ++i)
    targets.vertices.row(i) = frame_.mesh.vertices.row(targets.vertex_ids[i]);
  std::unique_ptr<ceres::CostFunction> cost(
      Points3dCost<>::Create(evaluator_, targets, 0.002));
  ExpectGradientsMatch(*cost, params_.Blocks(), 1e-6);
}

TEST_F(CostGradientsTest, Silhouette) {
  // A linear stand-in for a distance image (bilinear interpolation reproduces it
  // exactly, so no cell edges), with an outline of a few samples.
  std::vector<SilhouetteView> views(2);
  for (int v = 0; v < 2; ++v) {
    views[v].camera = frame_.views[v].camera;
    views[v].distance_to_mask.resize(480, 640);
    for (int y = 0; y < 480; ++y) {
      for (int x = 0; x < 640; ++x) {
        views[v].distance_to_mask(y, x) =
            0.02 * std::abs(x - 300.0) + 0.01 * std::abs(y - 200.0);
      }
    }
    for (int s = 0; s < 5; ++s) {
      views[v].outline_px.emplace_back(300 + 10 * s, 250 - 7 * s);
      views[v].outline_normal.push_back(Eigen::Vector2d(1, s).normalized());
      views[v].outline_vertex.push_back(2 * s + v);  // < ids.size()
    }
  }
  const std::vector<int> ids = {0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20};
  std::unique_ptr<ceres::CostFunction> cost(
      MultiViewSilhouetteCost<>::Create(evaluator_, ids, views, 2.0));
  ExpectGradientsMatch(*cost, params_.Blocks(), 1e-5);
  // The square-root form (analytic Jacobians) has autodiff's Gauss-Newton data.
  std::unique_ptr<ceres::CostFunction> fast(
      MultiViewSilhouetteSquareRootCost::Create(evaluator_, ids, views, 2.0));
  ExpectSameGaussNewton(*cost, *fast, params_.Blocks());

  // One-sided views (unknown occluders): mesh -> mask residuals saturate, outline
  // residuals only where the hand falls short of the outline; both versions agree and
  // match finite differences. (The cost functions hold `views` by reference: evaluate
  // the two-sided residuals before switching.)
  std::vector<double> two(cost->num_residuals()), one(cost->num_residuals());
  cost->Evaluate(params_.Blocks().data(), two.data(), nullptr);
  for (SilhouetteView& view : views) view.one_sided = true;
  std::unique_ptr<ceres::CostFunction> one_sided(
      MultiViewSilhouetteCost<>::Create(evaluator_, ids, views, 2.0));
  std::unique_ptr<ceres::CostFunction> one_sided_fast(
      MultiViewSilhouetteSquareRootCost::Create(evaluator_, ids, views, 2.0));
  ExpectSameGaussNewton(*one_sided, *one_sided_fast, params_.Blocks());
  ExpectGradientsMatch(*one_sided, params_.Blocks(), 1e-5);
  one_sided->Evaluate(params_.Blocks().data(), one.data(), nullptr);
  const size_t per_view = ids.size() + 5;
  int kept = 0;
  for (size_t r = 0; r < two.size(); ++r) {
    const bool outline = r % per_view >= ids.size();
    // Mesh -> mask: x / sigma becomes cap x / (cap + x) / sigma (cap 3 px, sigma 2 px).
    const double x = 2.0 * two[r];
    const double expected = outline ? std::min(two[r], 0.0) : 3.0 * x / (3.0 + x) / 2.0;
    EXPECT_NEAR(one[r], expected, 1e-12) << r;
    kept += outline && two[r] < 0;
  }
  EXPECT_GT(kept, 0);  // the scene has outline samples the hand falls short of
}

TEST_F(CostGradientsTest, SilhouetteDistanceWindow) {
  // The distance image of a window around the hand, smaller than the projected hand:
  // vertices beyond it take the border value plus the distance to the border. The
  // same checks as above (finite differences, square-root form), and the lookup
  // equals the full image's inside the window.
  const auto linear = [](double x, double y) {
    return 0.02 * std::abs(x - 300.0) + 0.01 * std::abs(y - 200.0);
  };
  std::vector<SilhouetteView> views(2);
  for (int v = 0; v < 2; ++v) {
    views[v].camera = frame_.views[v].camera;
    Eigen::Vector2d centre;
    ASSERT_TRUE(
        views[v].camera.ProjectWorld(frame_.mesh.vertices.row(0).transpose(), &centre));
    views[v].distance_origin = (centre - Eigen::Vector2d(20, 15)).cast<int>();
    views[v].distance_to_mask.resize(30, 40);
    for (int y = 0; y < 30; ++y) {
      for (int x = 0; x < 40; ++x) {
        views[v].distance_to_mask(y, x) =
            linear(x + views[v].distance_origin.x(), y + views[v].distance_origin.y());
      }
    }
  }
  const std::vector<int> ids = {0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20};
  std::unique_ptr<ceres::CostFunction> cost(
      MultiViewSilhouetteCost<>::Create(evaluator_, ids, views, 2.0));
  ExpectGradientsMatch(*cost, params_.Blocks(), 1e-5);
  std::unique_ptr<ceres::CostFunction> fast(
      MultiViewSilhouetteSquareRootCost::Create(evaluator_, ids, views, 2.0));
  ExpectSameGaussNewton(*cost, *fast, params_.Blocks());

  const SilhouetteView& view = views[0];
  const Eigen::Vector2d o = view.distance_origin.cast<double>();
  Eigen::Vector2d gradient;
  const Eigen::Vector2d inside = o + Eigen::Vector2d(10.3, 7.6);
  EXPECT_NEAR(DistanceWithGradient(view, inside, &gradient),
              linear(inside.x(), inside.y()), 1e-12);
  EXPECT_NEAR(DistanceLookup(view, inside.x(), inside.y()),
              linear(inside.x(), inside.y()), 1e-12);
  // 5 px left of and 12 px below the window's lower-left corner: 13 px beyond it.
  const Eigen::Vector2d beyond = o + Eigen::Vector2d(-5, 29 + 12);
  const double corner = linear(o.x(), o.y() + 29);
  EXPECT_NEAR(DistanceWithGradient(view, beyond, &gradient), corner + 13.0, 1e-12);
  EXPECT_THAT(gradient, testing::MatrixNear(Eigen::Vector2d(-5, 12) / 13.0, 1e-12));
  EXPECT_NEAR(DistanceLookup(view, beyond.x(), beyond.y()), corner + 13.0, 1e-12);
  int outside = 0;  // the scene has vertices beyond the window
  for (int i : ids) {
    Eigen::Vector2d uv;
    view.camera.ProjectWorld(frame_.mesh.vertices.row(i).transpose(), &uv);
    const Eigen::Vector2d x = uv - o;
    outside += x.x() < 0 || x.y() < 0 || x.x() > 39 || x.y() > 29;
  }
  EXPECT_GT(outside, 0);
}

TEST(AxisAngleManifoldTest, Invariants) {
  ceres::AutoDiffManifold<AxisAngleManifoldFunctor, 3, 3> manifold;
  for (int trial = 0; trial < 10; ++trial) {
    using Vector = Eigen::VectorXd;
    using namespace ceres;  // NOLINT: the macro names ceres matchers unqualified
    Vector x = testing::RandomVector3(-1.5, 1.5);
    Vector delta = testing::RandomVector3(-0.5, 0.5);
    Vector y = testing::RandomVector3(-1.5, 1.5);
    EXPECT_THAT_MANIFOLD_INVARIANTS_HOLD(manifold, x, delta, y, 1e-9);
  }
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

TEST(Keypoints3dCostFunctionTest, MatchesAutodiffPoints3d) {
  const HandModel model = testing::MakeStickHand(HandSide::kRight);
  const HandEvaluator evaluator(model);
  const testing::SceneFrame frame = testing::RandomSceneFrame(model, testing::TestRng());
  Points3dTargets targets;
  targets.keypoints = frame.mesh.keypoints;
  targets.keypoints.array() += 0.003;
  targets.keypoint_weights = Eigen::VectorXd::Ones(21);
  targets.keypoint_weights[7] = 0.25;
  std::unique_ptr<ceres::CostFunction> autodiff(
      Points3dCost<>::Create(evaluator, targets, 0.002));
  std::unique_ptr<ceres::CostFunction> analytic(Keypoints3dCostFunction::Create(
      evaluator, targets.keypoints, targets.keypoint_weights, 0.002));
  Params params = FromHandParams(frame.params);
  ExpectSameResidualsAndJacobians(*autodiff, *analytic, params.Blocks());
  ExpectGradientsMatch(*analytic, params.Blocks(), 1e-6);
}

}  // namespace
}  // namespace handlabel
