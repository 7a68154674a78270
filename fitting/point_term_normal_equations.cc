#include "fitting/point_term_normal_equations.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "core/errors.h"

namespace handlabel {

PointTermNormalEquations::PointTermNormalEquations(int num_points)
    : h_(num_points, Eigen::Matrix3d::Zero()),
      g_(num_points, Eigen::Vector3d::Zero()),
      used_(num_points, 0) {}

void PointTermNormalEquations::AddRow(int point, double r, const Eigen::Vector3d& a) {
  HL_CHECK(point >= 0 && point < static_cast<int>(used_.size()), "point index");
  squared_norm_ += r * r;
  if (a.isZero(0.0)) return;
  h_[point].noalias() += a * a.transpose();
  g_[point] += r * a;
  used_[point] = 1;
}

std::vector<int> PointTermNormalEquations::UsedPoints() const {
  std::vector<int> points;
  for (size_t i = 0; i < used_.size(); ++i) {
    if (used_[i]) points.push_back(static_cast<int>(i));
  }
  return points;
}

void PointTermNormalEquations::Accumulate(const double* point_jacobians, int n,
                                          Eigen::MatrixXd* jtj,
                                          Eigen::VectorXd* jtr) const {
  using PointJacobian =
      Eigen::Map<const Eigen::Matrix<double, 3, Eigen::Dynamic, Eigen::RowMajor>>;
  const std::vector<int> points = UsedPoints();
  // No point seen (every keypoint of every view at confidence 0: a frame where the
  // detector found no hand): J^T J and J^T r are zero. Eigen's rank update of an empty
  // matrix divides by its zero inner size (SIGFPE), so it is not called.
  if (points.empty()) {
    jtj->setZero(n, n);
    jtr->setZero(n);
    return;
  }
  // Each H_i = M M^T (M from its eigen-decomposition; H_i is positive semi-definite),
  // so its rows of J^T J are those of M^T dX_i: 3 rows per point in one rank update.
  Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor> rows(
      3 * points.size(), n);
  jtr->setZero(n);
  for (size_t k = 0; k < points.size(); ++k) {
    const PointJacobian dx(point_jacobians + 3 * k * n, 3, n);
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen;
    eigen.computeDirect(h_[points[k]]);
    const Eigen::Matrix3d m =
        eigen.eigenvectors() * eigen.eigenvalues().cwiseMax(0.0).cwiseSqrt().asDiagonal();
    rows.middleRows(3 * k, 3).noalias() = m.transpose() * dx;
    jtr->noalias() += dx.transpose() * g_[points[k]];
  }
  jtj->setZero(n, n);
  jtj->selfadjointView<Eigen::Lower>().rankUpdate(rows.transpose());
  *jtj = jtj->selfadjointView<Eigen::Lower>();
}

void WriteSquareRootForm(const Eigen::MatrixXd& jtj, const Eigen::VectorXd& jtr,
                         double squared_norm, const std::vector<int>& block_sizes,
                         double* residuals, double** jacobians) {
  const int n = static_cast<int>(jtj.rows());
  // Each diagonal entry grows by 1e-12 of itself (a column's own scale: Ceres scales
  // the columns of J to unit norm), an empty column by a negligible absolute amount.
  Eigen::MatrixXd regularised = jtj;
  for (int i = 0; i < n; ++i) {
    regularised(i, i) += jtj(i, i) > 0.0 ? 1e-12 * jtj(i, i) : 1e-200;
  }
  const Eigen::LLT<Eigen::MatrixXd> llt(regularised);
  HL_CHECK(llt.info() == Eigen::Success, "J^T J + eps I is positive definite");
  // r' solves R^T r' = J^T r with R = L^T.
  Eigen::Map<Eigen::VectorXd> reduced(residuals, n);
  reduced = llt.matrixL().solve(jtr);
  residuals[n] = std::sqrt(std::max(0.0, squared_norm - reduced.squaredNorm()));
  if (jacobians == nullptr) return;
  const Eigen::MatrixXd r = llt.matrixU();
  int offset = 0;
  for (size_t b = 0; b < block_sizes.size(); ++b) {
    const int size = block_sizes[b];
    if (jacobians[b] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>
          out(jacobians[b], n + 1, size);
      out.topRows(n) = r.middleCols(offset, size);
      out.row(n).setZero();
    }
    offset += size;
  }
  HL_CHECK(offset == n, "parameter blocks cover the normal equations");
}

void WriteCostOnly(double squared_norm, int num_residuals, double* residuals) {
  std::fill(residuals, residuals + num_residuals, 0.0);
  residuals[0] = std::sqrt(squared_norm);
}

void PointTermNormalEquations::WriteCeresOutput(const double* point_jacobians, int n,
                                                const std::vector<int>& block_sizes,
                                                double* residuals,
                                                double** jacobians) const {
  Eigen::MatrixXd jtj;
  Eigen::VectorXd jtr;
  Accumulate(point_jacobians, n, &jtj, &jtr);
  WriteSquareRootForm(jtj, jtr, squared_norm_, block_sizes, residuals, jacobians);
}

}  // namespace handlabel
