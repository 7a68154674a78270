#pragma once
// Triangle mesh of the zero level set of a scalar field (negative inside), by marching
// tetrahedra on a regular grid: each grid cube is split into 6 tetrahedra around its
// main diagonal, so neighbouring cubes share face diagonals and the output is a closed
// 2-manifold for a field that is nowhere exactly zero on the grid (values that are
// exactly zero are nudged outwards). Faces are counter-clockwise seen from outside.

#include <Eigen/Core>
#include <functional>
#include <vector>

namespace handlabel {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;
  std::vector<Eigen::Vector3i> faces;
};

struct ImplicitMesherOptions {
  double step = 0.0015;  // grid spacing (metres); must be > 0
  void Check(const std::string& source) const;
};

// Samples `field` on the grid covering [lo, hi] and extracts its zero set. The field
// must be positive on the box boundary for the mesh to be closed.
TriangleMesh MeshImplicitSurface(
    const std::function<double(const Eigen::Vector3d&)>& field, const Eigen::Vector3d& lo,
    const Eigen::Vector3d& hi, const ImplicitMesherOptions& options);

}  // namespace handlabel
