#include "fitting/folded_terms.h"

#include "core/errors.h"

namespace handlabel {

FoldedTerms::FoldedTerms(std::vector<int> host_block_sizes)
    : block_sizes_(std::move(host_block_sizes)) {
  int offset = 0;
  for (int size : block_sizes_) {
    block_offsets_.push_back(offset);
    offset += size;
  }
}

void FoldedTerms::Add(std::string name, ceres::CostFunction* cost, int block) {
  HL_CHECK(block >= 0 && block < static_cast<int>(block_sizes_.size()), "host block");
  HL_CHECK(cost->parameter_block_sizes().size() == 1 &&
               cost->parameter_block_sizes()[0] == block_sizes_[block],
           "a folded term reads exactly one host block");
  terms_.push_back({std::move(name), std::unique_ptr<ceres::CostFunction>(cost), block});
}

std::vector<double> FoldedTerms::Residuals(const FoldedTerm& term,
                                           double const* const* parameters,
                                           std::vector<double>* jacobian) const {
  std::vector<double> r(term.cost->num_residuals());
  const double* block = parameters[term.block];
  double* jacobians[1] = {nullptr};
  if (jacobian != nullptr) {
    jacobian->resize(r.size() * block_sizes_[term.block]);
    jacobians[0] = jacobian->data();
  }
  HL_CHECK(term.cost->Evaluate(&block, r.data(), jacobian ? jacobians : nullptr),
           "folded term " + term.name + " evaluates");
  return r;
}

double FoldedTerms::TermSquaredNorm(const FoldedTerm& term,
                                    double const* const* parameters) const {
  double sum = 0.0;
  for (double r : Residuals(term, parameters, nullptr)) sum += r * r;
  return sum;
}

double FoldedTerms::SquaredNorm(double const* const* parameters) const {
  double sum = 0.0;
  for (const FoldedTerm& term : terms_) sum += TermSquaredNorm(term, parameters);
  return sum;
}

void FoldedTerms::AddNormalEquations(double const* const* parameters,
                                     Eigen::MatrixXd* jtj, Eigen::VectorXd* jtr,
                                     double* squared_norm) const {
  std::vector<double> jacobian;
  for (const FoldedTerm& term : terms_) {
    const std::vector<double> r = Residuals(term, parameters, &jacobian);
    const int size = block_sizes_[term.block];
    const int offset = block_offsets_[term.block];
    const Eigen::Map<
        const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
        j(jacobian.data(), static_cast<Eigen::Index>(r.size()), size);
    // Row by row over the non-zero entries: the priors' Jacobians are diagonal or
    // block-diagonal (a 45 x 45 dense product per term cost more than Ceres saved).
    std::vector<int> nonzero;
    for (Eigen::Index i = 0; i < j.rows(); ++i) {
      *squared_norm += r[i] * r[i];
      nonzero.clear();
      for (int c = 0; c < size; ++c) {
        if (j(i, c) != 0.0) nonzero.push_back(c);
      }
      for (int a : nonzero) {
        (*jtr)[offset + a] += j(i, a) * r[i];
        for (int b : nonzero) (*jtj)(offset + a, offset + b) += j(i, a) * j(i, b);
      }
    }
  }
}

std::vector<std::pair<std::string, double>> FoldedTerms::Costs(
    double const* const* parameters) const {
  std::vector<std::pair<std::string, double>> costs;
  for (const FoldedTerm& term : terms_) {
    costs.emplace_back(term.name, 0.5 * TermSquaredNorm(term, parameters));
  }
  return costs;
}

}  // namespace handlabel
