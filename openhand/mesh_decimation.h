#pragma once
// Mesh simplification and smoothing for the open hand builder. Decimation uses
// OpenMesh's quadric-error decimater (private to the pipeline layer).

#include <functional>

#include "openhand/implicit_mesher.h"

namespace handlabel {

struct DecimationOptions {
  int target_vertices = 778;               // stop at this many vertices (MANO has 778)
  double max_normal_deviation_deg = 45.0;  // forbid collapses that turn a face more
  double min_aspect_ratio = 0.0;           // 0: off; else forbid faces thinner than this
  // Afterwards, flip edges between nearly coplanar faces (dihedral < 20 degrees) when
  // that raises their minimum angle.
  bool improve_by_flips = false;
  void Check(const std::string& source) const;
};

// Collapses edges in order of quadric error until `target_vertices` remain. The input
// must be a closed manifold triangle mesh; the output is one as well. Deterministic.
TriangleMesh DecimateMesh(const TriangleMesh& mesh, const DecimationOptions& options);

// Tangential relaxation: moves every vertex towards the centroid of its neighbours
// within its tangent plane, then back onto the surface with `project`. Evens out
// triangle sizes without changing the shape.
void RelaxMesh(TriangleMesh* mesh, int iterations,
               const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& project);

// Per-vertex unit normals (area weighted face normals).
std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh);
// Neighbours of every vertex (sorted ids).
std::vector<std::vector<int>> VertexNeighbours(const TriangleMesh& mesh);

}  // namespace handlabel
