#include "openhand/nnls.h"

#include <Eigen/QR>
#include <vector>

#include "core/errors.h"

namespace handlabel {
namespace {

// Least squares on the columns in `passive`, zero elsewhere.
Eigen::VectorXd SolvePassive(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                             const std::vector<bool>& passive) {
  std::vector<int> cols;
  for (int j = 0; j < static_cast<int>(passive.size()); ++j)
    if (passive[j]) cols.push_back(j);
  Eigen::MatrixXd sub(a.rows(), static_cast<Eigen::Index>(cols.size()));
  for (size_t k = 0; k < cols.size(); ++k) sub.col(k) = a.col(cols[k]);
  const Eigen::VectorXd zs = sub.colPivHouseholderQr().solve(b);
  Eigen::VectorXd z = Eigen::VectorXd::Zero(a.cols());
  for (size_t k = 0; k < cols.size(); ++k) z[cols[k]] = zs[k];
  return z;
}

}  // namespace

Eigen::VectorXd SolveNnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                          int max_iterations) {
  HL_CHECK(a.rows() == b.size(), "NNLS: rows of A and b differ");
  const int n = static_cast<int>(a.cols());
  if (max_iterations <= 0) max_iterations = 3 * n + 10;
  const double tol = 1e-12 * (1.0 + a.cwiseAbs().maxCoeff()) * (1.0 + b.norm());
  Eigen::VectorXd x = Eigen::VectorXd::Zero(n);
  std::vector<bool> passive(n, false);
  for (int outer = 0; outer < max_iterations; ++outer) {
    const Eigen::VectorXd w = a.transpose() * (b - a * x);
    int best = -1;
    for (int j = 0; j < n; ++j) {
      if (!passive[j] && w[j] > tol && (best < 0 || w[j] > w[best])) best = j;
    }
    if (best < 0) break;  // KKT conditions hold
    passive[best] = true;
    for (int inner = 0; inner <= n; ++inner) {
      const Eigen::VectorXd z = SolvePassive(a, b, passive);
      bool feasible = true;
      for (int j = 0; j < n; ++j)
        if (passive[j] && z[j] <= 0) feasible = false;
      if (feasible) {
        x = z;
        break;
      }
      // Step from x towards z until the first passive variable hits zero.
      double alpha = 1.0;
      for (int j = 0; j < n; ++j) {
        if (passive[j] && z[j] <= 0) alpha = std::min(alpha, x[j] / (x[j] - z[j]));
      }
      x += alpha * (z - x);
      for (int j = 0; j < n; ++j) {
        if (passive[j] && x[j] <= 1e-15) {
          passive[j] = false;
          x[j] = 0.0;
        }
      }
    }
  }
  return x;
}

}  // namespace handlabel
