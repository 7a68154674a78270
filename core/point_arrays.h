#pragma once
// The project's one type for a list of 3D points and one for a list of triangles, both
// row-major so that a row is a point (or a face) and the data is x0 y0 z0 x1 ... as
// files and Ceres parameter blocks store it.

#include <Eigen/Core>

namespace handlabel {

// N x 3 points (vertices, joints, keypoints), metres unless a field says otherwise.
using Points3d = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
// F x 3 vertex indices of triangles.
using Faces = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;

}  // namespace handlabel
