#include "openhand/implicit_mesher.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {

void ImplicitMesherOptions::Check(const std::string& source) const {
  RequireGreater(source, "step", step, 0, "a positive grid spacing");
}

namespace {

// The sample grid: n samples per axis from lo with spacing h, values in x-fastest order.
class SampleGrid {
 public:
  SampleGrid(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, double h)
      : lo_(lo), h_(h), n_(((hi - lo) / h).array().ceil().cast<int>() + 1) {
    HL_CHECK(n_.minCoeff() >= 2, "grid must have at least 2 samples per axis");
  }
  const Eigen::Vector3i& n() const { return n_; }
  int64_t Index(int x, int y, int z) const {
    return (static_cast<int64_t>(z) * n_.y() + y) * n_.x() + x;
  }
  Eigen::Vector3d Point(int64_t i) const {
    const int x = static_cast<int>(i % n_.x());
    const int y = static_cast<int>((i / n_.x()) % n_.y());
    const int z = static_cast<int>(i / (static_cast<int64_t>(n_.x()) * n_.y()));
    return Eigen::Vector3d(lo_.x() + x * h_, lo_.y() + y * h_, lo_.z() + z * h_);
  }
  // The field at every sample, nudged off zero so no sample lies on the surface.
  std::vector<float> Sample(
      const std::function<double(const Eigen::Vector3d&)>& field) const {
    std::vector<float> values(static_cast<size_t>(n_.x()) * n_.y() * n_.z());
    for (int z = 0; z < n_.z(); ++z) {
      for (int y = 0; y < n_.y(); ++y) {
        for (int x = 0; x < n_.x(); ++x) {
          const int64_t i = Index(x, y, z);
          float v = static_cast<float>(field(Point(i)));
          if (v == 0.0f) v = 1e-9f;  // never exactly on the surface
          values[i] = v;
        }
      }
    }
    return values;
  }

 private:
  Eigen::Vector3d lo_;
  double h_;
  Eigen::Vector3i n_;
};

// Marching tetrahedra over the grid's cubes; surface vertices are shared between the
// triangles that cut the same grid edge.
class TetMesher {
 public:
  TetMesher(const SampleGrid& grid, std::vector<float> values)
      : grid_(grid), values_(std::move(values)) {}

  TriangleMesh Run() {
    const Eigen::Vector3i& n = grid_.n();
    for (int z = 0; z + 1 < n.z(); ++z) {
      for (int y = 0; y + 1 < n.y(); ++y) {
        for (int x = 0; x + 1 < n.x(); ++x) MeshCube(x, y, z);
      }
    }
    return std::move(mesh_);
  }

 private:
  void MeshCube(int x, int y, int z) {
    // Cube corner c has offset (c & 1, (c >> 1) & 1, (c >> 2) & 1); the 6 tetrahedra
    // are the paths 0 -> e_a -> e_a + e_b -> 7 over the axis permutations (a, b).
    static const int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                    {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
    std::array<int64_t, 8> corner;
    bool any_in = false, any_out = false;
    for (int c = 0; c < 8; ++c) {
      corner[c] = grid_.Index(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1));
      (values_[corner[c]] < 0 ? any_in : any_out) = true;
    }
    if (!any_in || !any_out) return;
    for (const auto& tet : kTets) {
      MeshTet({corner[tet[0]], corner[tet[1]], corner[tet[2]], corner[tet[3]]});
    }
  }

  void MeshTet(const std::array<int64_t, 4>& tet) {
    std::array<int64_t, 4> in, out;
    int num_in = 0, num_out = 0;
    for (int k = 0; k < 4; ++k) {
      const int64_t g = tet[k];
      if (values_[g] < 0) {
        in[num_in++] = g;
      } else {
        out[num_out++] = g;
      }
    }
    if (num_in == 0 || num_out == 0) return;
    Eigen::Vector3d in_c = Eigen::Vector3d::Zero(), out_c = Eigen::Vector3d::Zero();
    for (int k = 0; k < num_in; ++k) in_c += grid_.Point(in[k]) / num_in;
    for (int k = 0; k < num_out; ++k) out_c += grid_.Point(out[k]) / num_out;
    const Eigen::Vector3d outward = out_c - in_c;
    if (num_in == 1 || num_out == 1) {
      // One corner separated from three: one triangle.
      const bool single_in = num_in == 1;
      const int64_t s = single_in ? in[0] : out[0];
      const auto& others = single_in ? out : in;
      AddTriangle(VertexOnEdge(s, others[0]), VertexOnEdge(s, others[1]),
                  VertexOnEdge(s, others[2]), outward);
    } else {
      // Two against two: a quad (in0-out0, in0-out1, in1-out1, in1-out0).
      const int a = VertexOnEdge(in[0], out[0]);
      const int b = VertexOnEdge(in[0], out[1]);
      const int c = VertexOnEdge(in[1], out[1]);
      const int d = VertexOnEdge(in[1], out[0]);
      AddTriangle(a, b, c, outward);
      AddTriangle(a, c, d, outward);
    }
  }

  // The surface vertex on grid edge (a, b), interpolated linearly, made once.
  int VertexOnEdge(int64_t a, int64_t b) {
    if (a > b) std::swap(a, b);
    const uint64_t key =
        static_cast<uint64_t>(a) * values_.size() + static_cast<uint64_t>(b);
    auto it = edge_vertex_.find(key);
    if (it != edge_vertex_.end()) return it->second;
    const double fa = values_[a], fb = values_[b];
    const double t = fa / (fa - fb);
    mesh_.vertices.push_back(grid_.Point(a) + t * (grid_.Point(b) - grid_.Point(a)));
    const int id = static_cast<int>(mesh_.vertices.size()) - 1;
    edge_vertex_.emplace(key, id);
    return id;
  }

  // Adds triangle (a, b, c) turned so its normal points along `outward`.
  void AddTriangle(int a, int b, int c, const Eigen::Vector3d& outward) {
    const Eigen::Vector3d nrm = (mesh_.vertices[b] - mesh_.vertices[a])
                                    .cross(mesh_.vertices[c] - mesh_.vertices[a]);
    if (nrm.dot(outward) < 0) std::swap(b, c);
    mesh_.faces.emplace_back(a, b, c);
  }

  const SampleGrid& grid_;
  const std::vector<float> values_;
  TriangleMesh mesh_;
  std::unordered_map<uint64_t, int> edge_vertex_;
};

}  // namespace

TriangleMesh MeshImplicitSurface(
    const std::function<double(const Eigen::Vector3d&)>& field, const Eigen::Vector3d& lo,
    const Eigen::Vector3d& hi, const ImplicitMesherOptions& options) {
  options.Check("implicit mesher options");
  const SampleGrid grid(lo, hi, options.step);
  return TetMesher(grid, grid.Sample(field)).Run();
}

}  // namespace handlabel
