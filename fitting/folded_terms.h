#pragma once
// Small terms on one parameter block each (the pose and shape priors, the joint
// limits), folded into a square-root term's block (point_term_normal_equations.h)
// instead of being residual blocks of their own. Ceres' dense normal equations cost
// grows with the rows of J: a keypoint stage had 62 square-root rows plus 100 prior
// rows (45 joint limits, 45 pose prior, 10 shape prior), most of Ceres' J^T J work.
// Folded, the same cost, gradient and Gauss-Newton matrix arrive in 62 rows.

#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

namespace handlabel {

struct FoldedTerm {
  std::string name;                           // reported as its own term
  std::unique_ptr<ceres::CostFunction> cost;  // exactly one parameter block
  int block = 0;                              // which of the host's blocks it reads
};

class FoldedTerms {
 public:
  // `host_block_sizes`: the host cost's parameter blocks, in order.
  explicit FoldedTerms(std::vector<int> host_block_sizes);

  void Add(std::string name, ceres::CostFunction* cost, int block);
  bool empty() const { return terms_.empty(); }

  // Sum of squared residuals of every term at `parameters` (the host's blocks).
  double SquaredNorm(double const* const* parameters) const;
  // Adds every term's J^T J, J^T r and |r|^2 to the host's normal equations (the host's
  // blocks laid out one after the other).
  void AddNormalEquations(double const* const* parameters, Eigen::MatrixXd* jtj,
                          Eigen::VectorXd* jtr, double* squared_norm) const;
  // Ceres' cost (half the squared norm) of each term, by name.
  std::vector<std::pair<std::string, double>> Costs(
      double const* const* parameters) const;

 private:
  std::vector<double> Residuals(const FoldedTerm& term, double const* const* parameters,
                                std::vector<double>* jacobian) const;
  double TermSquaredNorm(const FoldedTerm& term, double const* const* parameters) const;

  std::vector<int> block_sizes_;
  std::vector<int> block_offsets_;
  std::vector<FoldedTerm> terms_;
};

}  // namespace handlabel
