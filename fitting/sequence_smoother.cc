#include "fitting/sequence_smoother.h"

#include <ceres/ceres.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "core/errors.h"
#include "core/option_checks.h"
#include "fitting/acceleration_cost.h"
#include "fitting/axis_angle_manifold.h"
#include "fitting/fit_run.h"
#include "fitting/joint_limit_cost.h"
#include "fitting/keypoint_reprojection_cost.h"
#include "fitting/prior_costs.h"
#include "hand/hand_skeleton.h"
#include "hand/metrics.h"

namespace handlabel {
namespace {

constexpr int kShapeBetas = 10;  // the fitter's betas (fitting/stage_problem.h kBetas)
constexpr int kBones = kNumHandKeypoints - 1;

// Bone lengths of the hand with shape `betas` at one frame's pose (orientation and
// place do not change lengths) minus the target lengths, per bone_sigma.
class BoneLengthResidual {
 public:
  BoneLengthResidual(const HandEvaluator& evaluator, const HandParams& pose_of,
                     const Eigen::VectorXd& target_m, double sigma_m)
      : evaluator_(evaluator),
        pose_(pose_of.hand_pose),
        target_(target_m),
        inv_sigma_(1.0 / sigma_m) {}

  template <typename T>
  bool operator()(const T* betas, T* residuals) const {
    using std::sqrt;
    T orient[3] = {T(0), T(0), T(0)}, transl[3] = {T(0), T(0), T(0)};
    T pose[kNumPoseParams];
    for (int i = 0; i < kNumPoseParams; ++i) pose[i] = T(pose_[i]);
    T k[3 * kNumHandKeypoints];
    evaluator_.Keypoints(orient, pose, betas, transl, k);
    for (int b = 1; b < kNumHandKeypoints; ++b) {
      const int p = kSnapParents[b];
      T squared(0);
      for (int c = 0; c < 3; ++c) {
        const T d = k[3 * b + c] - k[3 * p + c];
        squared += d * d;
      }
      residuals[b - 1] = (sqrt(squared) - T(target_[b - 1])) * T(inv_sigma_);
    }
    return true;
  }

 private:
  const HandEvaluator& evaluator_;
  Eigen::Matrix<double, kNumPoseParams, 1> pose_;
  Eigen::VectorXd target_;
  double inv_sigma_;
};

// Per bone, the median over frames of the bone's length.
Eigen::VectorXd MedianBoneLengths(const std::vector<Points3d>& keypoints) {
  std::vector<Eigen::VectorXd> lengths;
  for (const Points3d& k : keypoints) lengths.push_back(BoneLengths(k));
  Eigen::VectorXd median(kBones);
  std::vector<double> values(lengths.size());
  for (int b = 0; b < kBones; ++b) {
    for (size_t f = 0; f < lengths.size(); ++f) values[f] = lengths[f][b];
    const auto middle = values.begin() + values.size() / 2;
    std::nth_element(values.begin(), middle, values.end());
    median[b] = *middle;
  }
  return median;
}

ceres::Solver::Options WindowSolverOptions(const HandFitOptions& fit, int iterations) {
  ceres::Solver::Options s;
  s.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  // Eigen's sparse Cholesky: no BLAS threads, so the same bits at any thread count.
  s.sparse_linear_algebra_library_type = ceres::EIGEN_SPARSE;
  s.max_num_iterations = iterations;
  s.function_tolerance = fit.function_tolerance;
  s.parameter_tolerance = fit.parameter_tolerance;
  s.gradient_tolerance = 1e-12;
  s.num_threads = 1;
  s.logging_type = ceres::SILENT;
  return s;
}

}  // namespace

struct SequenceSmoother::FrameBlocks {
  double orient[3];
  double pose[kNumPoseParams];
  double transl[3];
};

void SequenceSmoothOptions::Check(const std::string& source) const {
  RequireGreater(source, "acceleration_sigma_mm", acceleration_sigma_mm, 0);
  RequireAtLeast(source, "iterations", iterations, 1);
  RequireAtLeast(source, "shape_frames", shape_frames, 1);
  RequireGreater(source, "bone_sigma_mm", bone_sigma_mm, 0);
}

SequenceSmoother::SequenceSmoother(const HandModel& model, const HandFitConfig& config,
                                   const HandFitOptions& fit,
                                   const SequenceSmoothOptions& options,
                                   std::optional<DetectorKeypointModel> detector)
    : model_(model),
      config_(config),
      fit_(fit),
      options_(options),
      evaluator_(model,
                 [&] {
                   config.Check("HandFitConfig");
                   fit.Check("HandFitOptions");
                   options.Check("SequenceSmoothOptions");
                   if (config.pose_pca_comps != 0) {
                     throw InputError("SequenceSmoother", "fit.pose_pca_comps",
                                      "0 (the smoother fits 45 axis-angle values)",
                                      std::to_string(config.pose_pca_comps));
                   }
                   if (model.num_betas() < kShapeBetas) {
                     throw InputError(model.name, "shapedirs",
                                      "at least 10 shape coefficients",
                                      std::to_string(model.num_betas()));
                   }
                   HandEvaluatorOptions o;
                   o.num_betas = kShapeBetas;
                   return o;
                 }()),
      anatomy_(ComputeHandAnatomy(model)),
      limits_(DefaultHandLimits()),
      detector_(std::move(detector)) {
  if (detector_) detector_->Check("detector keypoint model", model.num_vertices());
}

Eigen::VectorXd SequenceSmoother::SequenceShape(
    const std::vector<Points3d>& keypoints, const std::vector<HandParams>& params) const {
  HL_CHECK(!keypoints.empty() && keypoints.size() == params.size(),
           "one set of keypoints and parameters per frame, at least one frame");
  const Eigen::VectorXd target = MedianBoneLengths(keypoints);
  // From the mean shape: bone lengths are nearly linear in the betas.
  Eigen::VectorXd betas = Eigen::VectorXd::Zero(kShapeBetas);
  ceres::Problem problem;
  problem.AddParameterBlock(betas.data(), kShapeBetas);
  const int count = std::min<int>(options_.shape_frames, params.size());
  for (int i = 0; i < count; ++i) {
    // Evenly spread frames, the same ones for the same input.
    const size_t f = (2 * i + 1) * params.size() / (2 * count);
    problem.AddResidualBlock(
        new ceres::AutoDiffCostFunction<BoneLengthResidual, kBones, kShapeBetas>(
            new BoneLengthResidual(evaluator_, params[f], target,
                                   options_.bone_sigma_mm / 1000.0)),
        nullptr, betas.data());
  }
  // The per-frame fits' shape prior, counted once per evaluated frame.
  for (int i = 0; i < count; ++i) {
    problem.AddResidualBlock(ShapePriorCost<kShapeBetas>::Create(fit_.shape_prior_sigma),
                             nullptr, betas.data());
  }
  ceres::Solver::Options s;
  s.linear_solver_type = ceres::DENSE_QR;
  s.max_num_iterations = 100;
  s.num_threads = 1;
  s.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(s, &problem, &summary);
  return betas;
}

void SequenceSmoother::AddFrame(const SmoothFrame& frame, FrameBlocks* b, double* shape,
                                ceres::Problem* problem) const {
  const HandParams& p = frame.start;
  std::copy_n(p.global_orient.data(), 3, b->orient);
  std::copy_n(p.hand_pose.data(), kNumPoseParams, b->pose);
  std::copy_n(p.transl.data(), 3, b->transl);
  problem->AddParameterBlock(b->orient, 3, CreateAxisAngleManifold());
  problem->AddParameterBlock(b->pose, kNumPoseParams);
  problem->AddParameterBlock(b->transl, 3);
  // The per-frame fit's keypoint stage term, priors folded in as there
  // (fitting/fit_run.h ForEachPrior; the shape prior apart: the shape is shared).
  auto* keypoints = new MultiViewKeypointSquareRootCost(
      evaluator_, frame.views, fit_.keypoint_loss, fit_.keypoint_sigma_px,
      detector_ ? &*detector_ : nullptr);
  if (config_.use_joint_limits) {
    const double limit_weight = 1.0 / std::pow(fit_.limit_sigma_deg * M_PI / 180.0, 2);
    keypoints->folded()->Add("joint_limits",
                             JointLimitCost<kNumPoseParams>::Create(
                                 evaluator_, anatomy_, limits_, limit_weight),
                             1);
  }
  if (config_.use_pose_prior) {
    const Eigen::Matrix<double, 45, 1> inv_pose_sigma =
        Eigen::Matrix<double, 45, 1>::Constant(1.0 / fit_.pose_prior_sigma_rad);
    keypoints->folded()->Add(
        "pose_prior",
        PosePriorCost<kNumPoseParams>::Create(
            evaluator_, fitting_internal::PoseMean(model_), inv_pose_sigma),
        1);
  }
  problem->AddResidualBlock(keypoints, nullptr, b->orient, b->pose, shape, b->transl);
}

Eigen::VectorXd SequenceSmoother::SequenceShapeFromEvidence(
    const std::vector<SmoothFrame>& frames) const {
  HL_CHECK(!frames.empty(), "at least one frame");
  Eigen::VectorXd shape = Eigen::VectorXd::Zero(kShapeBetas);
  const Eigen::VectorXd& start = frames[0].start.betas;
  for (Eigen::Index i = 0; i < std::min<Eigen::Index>(start.size(), kShapeBetas); ++i) {
    shape[i] = start[i];
  }
  std::vector<FrameBlocks> blocks(frames.size());
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(shape.data(), kShapeBetas);
  for (size_t f = 0; f < frames.size(); ++f) {
    AddFrame(frames[f], &blocks[f], shape.data(), &problem);
    problem.AddResidualBlock(ShapePriorCost<kShapeBetas>::Create(fit_.shape_prior_sigma),
                             nullptr, shape.data());
  }
  ceres::Solver::Summary summary;
  ceres::Solve(WindowSolverOptions(fit_, options_.iterations), &problem, &summary);
  return shape;
}

SmoothWindowResult SequenceSmoother::SmoothWindow(const std::vector<SmoothFrame>& frames,
                                                  const Eigen::VectorXd& betas) const {
  HL_CHECK(betas.size() == kShapeBetas, "10 betas");
  const int n = static_cast<int>(frames.size());
  std::vector<FrameBlocks> blocks(n);
  Eigen::VectorXd shape = betas;
  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddParameterBlock(shape.data(), kShapeBetas);
  problem.SetParameterBlockConstant(shape.data());
  for (int f = 0; f < n; ++f) AddFrame(frames[f], &blocks[f], shape.data(), &problem);
  for (int f = 1; f + 1 < n; ++f) {
    problem.AddResidualBlock(
        new KeypointAccelerationCost(evaluator_, shape,
                                     options_.acceleration_sigma_mm / 1000.0),
        nullptr,
        {blocks[f - 1].orient, blocks[f - 1].pose, blocks[f - 1].transl, blocks[f].orient,
         blocks[f].pose, blocks[f].transl, blocks[f + 1].orient, blocks[f + 1].pose,
         blocks[f + 1].transl});
  }
  ceres::Solver::Summary summary;
  ceres::Solve(WindowSolverOptions(fit_, options_.iterations), &problem, &summary);
  SmoothWindowResult result;
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  for (const FrameBlocks& b : blocks) {
    HandParams p;
    p.global_orient = Eigen::Vector3d(b.orient);
    p.hand_pose = Eigen::Map<const Eigen::Matrix<double, kNumPoseParams, 1>>(b.pose);
    p.transl = Eigen::Vector3d(b.transl);
    p.betas = shape;
    result.params.push_back(p);
  }
  return result;
}

}  // namespace handlabel
