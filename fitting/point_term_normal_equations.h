#pragma once
// Least-squares terms whose residuals depend on the parameters only through a few 3D
// points X_i (the hand's keypoints, mesh vertices): every residual row r depends on one
// point, d r / d theta = a^T d X_i / d theta with a 3-vector a. Their Gauss-Newton data
// then needs only a 3 x 3 matrix and a 3-vector per point,
//   J^T J = sum_i dX_i^T H_i dX_i,   J^T r = sum_i dX_i^T g_i,
//   H_i = sum a a^T,  g_i = sum a r   (over the rows of point i),
// instead of one row of J per residual (8 views x 509 silhouette rows, 8 x 42 keypoint
// rows).
//
// Such a term is handed to Ceres in square-root form, n + 1 residuals for n parameters:
//   r' = R^-T J^T r with Jacobian R (R^T R = J^T J), and one more residual
//   sqrt(|r|^2 - |r'|^2) with a zero Jacobian.
// It has the same cost, gradient J^T r and Gauss-Newton matrix J^T J at the point of
// linearisation (for every subset of free parameters), so Levenberg-Marquardt takes the
// same steps, while Ceres' dense linear algebra handles n + 1 rows instead of
// thousands. Evaluations without Jacobians (trial points) only need the cost:
// r' = (|r|, 0, ..., 0). R comes from a Cholesky factorisation of J^T J with its
// diagonal raised by 1e-12 of itself (J^T J may be singular: a parameter no row sees),
// which leaves |r'| <= |r|.

#include <Eigen/Core>
#include <vector>

namespace handlabel {

class PointTermNormalEquations {
 public:
  // `num_points`: points the rows may name (0 .. num_points - 1).
  explicit PointTermNormalEquations(int num_points);

  // One residual row r of point `point` with d r / d X_point = a.
  void AddRow(int point, double r, const Eigen::Vector3d& a);
  // A residual whose derivative is zero (it counts in the cost only).
  void AddConstant(double r) { squared_norm_ += r * r; }

  double squared_norm() const { return squared_norm_; }
  // Points with at least one row, in increasing order: only their Jacobians are needed.
  std::vector<int> UsedPoints() const;

  // J^T J (n x n) and J^T r from the used points' Jacobians: `point_jacobians` holds
  // 3 x n row-major blocks, one per entry of UsedPoints(), in that order.
  void Accumulate(const double* point_jacobians, int n, Eigen::MatrixXd* jtj,
                  Eigen::VectorXd* jtr) const;
  // Accumulate, then WriteSquareRootForm (below): a cost function's whole output.
  void WriteCeresOutput(const double* point_jacobians, int n,
                        const std::vector<int>& block_sizes, double* residuals,
                        double** jacobians) const;

 private:
  std::vector<Eigen::Matrix3d> h_;
  std::vector<Eigen::Vector3d> g_;
  std::vector<char> used_;
  double squared_norm_ = 0.0;
};

// Writes the square-root form (header comment) as a Ceres cost function's output:
// `residuals` holds jtj.rows() + 1 values; jacobians[b] (row-major, (n + 1) x
// block_sizes[b]) is skipped where nullptr. Block b covers the parameters
// [sum of earlier sizes, + block_sizes[b]).
void WriteSquareRootForm(const Eigen::MatrixXd& jtj, const Eigen::VectorXd& jtr,
                         double squared_norm, const std::vector<int>& block_sizes,
                         double* residuals, double** jacobians);

// The residuals of an evaluation without Jacobians: the same cost, (|r|, 0, ..., 0).
void WriteCostOnly(double squared_norm, int num_residuals, double* residuals);

}  // namespace handlabel
