#pragma once
// Non-negative least squares: min ||A x - b|| subject to x >= 0, by the active-set
// method of Lawson and Hanson (1974). For the small dense problems of model building
// (tens of unknowns).

#include <Eigen/Core>

namespace handlabel {

// Returns x >= 0. `max_iterations` bounds the outer loop (3 * columns is plenty).
Eigen::VectorXd SolveNnls(const Eigen::MatrixXd& a, const Eigen::VectorXd& b,
                          int max_iterations = 0);

}  // namespace handlabel
