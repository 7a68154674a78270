#pragma once
// One Ceres problem per fitting stage over the hand's parameter blocks (internal to
// fitting/ceres_hand_fitter.cc): the blocks, the solver options of a stage, and the
// problem that names its terms so each term's cost can be reported.

#include <ceres/ceres.h>

#include <map>
#include <memory>
#include <string>
#include <vector>

#include "fitting/axis_angle_manifold.h"
#include "fitting/ceres_hand_fitter.h"
#include "fitting/folded_terms.h"

namespace handlabel {

constexpr int kBetas = 10;

// The optimised parameter blocks.
struct Blocks {
  double orient[3] = {0, 0, 0};
  std::vector<double> pose;
  double betas[kBetas] = {};
  double transl[3] = {0, 0, 0};
};

inline ceres::Solver::Options SolverOptions(const HandFitOptions& o, int iterations) {
  ceres::Solver::Options s;
  s.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  s.max_num_iterations = iterations;
  s.function_tolerance = o.function_tolerance;
  s.parameter_tolerance = o.parameter_tolerance;
  s.gradient_tolerance = 1e-12;
  s.num_threads = o.num_threads;
  s.logging_type = ceres::SILENT;
  s.minimizer_progress_to_stdout = false;
  return s;
}

// One stage's problem over the blocks, with the terms named for the result.
class StageProblem {
 public:
  explicit StageProblem(Blocks* blocks) : blocks_(blocks) {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(options);
    problem_->AddParameterBlock(blocks->orient, 3, CreateAxisAngleManifold());
    problem_->AddParameterBlock(blocks->pose.data(),
                                static_cast<int>(blocks->pose.size()));
    problem_->AddParameterBlock(blocks->betas, kBetas);
    problem_->AddParameterBlock(blocks->transl, 3);
  }
  // `folded`: terms evaluated inside `cost` (folded_terms.h), reported on their own.
  void AddFull(const std::string& term, ceres::CostFunction* cost,
               const FoldedTerms* folded = nullptr) {
    ids_[term].push_back(problem_->AddResidualBlock(cost, nullptr, blocks_->orient,
                                                    blocks_->pose.data(), blocks_->betas,
                                                    blocks_->transl));
    if (folded != nullptr && !folded->empty()) folded_.emplace_back(term, folded);
  }
  void Add(const std::string& term, ceres::CostFunction* cost, double* block) {
    ids_[term].push_back(problem_->AddResidualBlock(cost, nullptr, block));
  }
  void Hold(double* block) { problem_->SetParameterBlockConstant(block); }

  ceres::Solver::Summary Solve(const ceres::Solver::Options& options) {
    ceres::Solver::Summary summary;
    ceres::Solve(options, problem_.get(), &summary);
    return summary;
  }
  std::map<std::string, double> TermCosts() const {
    std::map<std::string, double> costs;
    for (const auto& [term, ids] : ids_) {
      double total = 0.0;
      for (ceres::ResidualBlockId id : ids) {
        double cost = 0.0;
        problem_->EvaluateResidualBlock(id, false, &cost, nullptr, nullptr);
        total += cost;
      }
      costs[term] = total;
    }
    const double* params[] = {blocks_->orient, blocks_->pose.data(), blocks_->betas,
                              blocks_->transl};
    for (const auto& [host, folded] : folded_) {
      for (const auto& [term, cost] : folded->Costs(params)) {
        costs[term] += cost;
        costs[host] -= cost;
      }
    }
    return costs;
  }

 private:
  Blocks* blocks_;
  std::unique_ptr<ceres::Problem> problem_;
  std::map<std::string, std::vector<ceres::ResidualBlockId>> ids_;
  std::vector<std::pair<std::string, const FoldedTerms*>> folded_;
};

inline bool IsDone(const ceres::Solver::Summary& s) {
  return s.termination_type == ceres::CONVERGENCE ||
         s.termination_type == ceres::USER_SUCCESS;
}

}  // namespace handlabel
