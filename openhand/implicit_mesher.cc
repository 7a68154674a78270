#include "openhand/implicit_mesher.h"

#include <Eigen/Geometry>
#include <array>
#include <cmath>
#include <unordered_map>

#include "core/errors.h"

namespace handlabel {

void ImplicitMesherOptions::Check() const {
  if (!(step > 0.0)) {
    throw InputError("implicit mesher options", "step", "a positive grid spacing",
                     std::to_string(step));
  }
}

TriangleMesh MeshImplicitSurface(
    const std::function<double(const Eigen::Vector3d&)>& field, const Eigen::Vector3d& lo,
    const Eigen::Vector3d& hi, const ImplicitMesherOptions& options) {
  options.Check();
  const double h = options.step;
  const Eigen::Vector3i n = ((hi - lo) / h).array().ceil().cast<int>() + 1;
  HL_CHECK(n.minCoeff() >= 2, "grid must have at least 2 samples per axis");
  auto grid_index = [&](int x, int y, int z) {
    return (static_cast<int64_t>(z) * n.y() + y) * n.x() + x;
  };
  auto grid_point = [&](int64_t i) {
    const int x = static_cast<int>(i % n.x());
    const int y = static_cast<int>((i / n.x()) % n.y());
    const int z = static_cast<int>(i / (static_cast<int64_t>(n.x()) * n.y()));
    return Eigen::Vector3d(lo.x() + x * h, lo.y() + y * h, lo.z() + z * h);
  };
  std::vector<float> values(static_cast<size_t>(n.x()) * n.y() * n.z());
  for (int z = 0; z < n.z(); ++z) {
    for (int y = 0; y < n.y(); ++y) {
      for (int x = 0; x < n.x(); ++x) {
        const int64_t i = grid_index(x, y, z);
        float v = static_cast<float>(field(grid_point(i)));
        if (v == 0.0f) v = 1e-9f;  // never exactly on the surface
        values[i] = v;
      }
    }
  }

  TriangleMesh mesh;
  std::unordered_map<uint64_t, int> edge_vertex;
  auto vertex_on_edge = [&](int64_t a, int64_t b) {
    if (a > b) std::swap(a, b);
    const uint64_t key =
        static_cast<uint64_t>(a) * values.size() + static_cast<uint64_t>(b);
    auto it = edge_vertex.find(key);
    if (it != edge_vertex.end()) return it->second;
    const double fa = values[a], fb = values[b];
    const double t = fa / (fa - fb);
    mesh.vertices.push_back(grid_point(a) + t * (grid_point(b) - grid_point(a)));
    const int id = static_cast<int>(mesh.vertices.size()) - 1;
    edge_vertex.emplace(key, id);
    return id;
  };
  // Adds triangle (a, b, c) turned so its normal points from `inside` to `outside`.
  auto add_triangle = [&](int a, int b, int c, const Eigen::Vector3d& outward) {
    const Eigen::Vector3d nrm =
        (mesh.vertices[b] - mesh.vertices[a]).cross(mesh.vertices[c] - mesh.vertices[a]);
    if (nrm.dot(outward) < 0) std::swap(b, c);
    mesh.faces.emplace_back(a, b, c);
  };

  // Cube corner c has offset (c & 1, (c >> 1) & 1, (c >> 2) & 1); the 6 tetrahedra are
  // the paths 0 -> e_a -> e_a + e_b -> 7 over the axis permutations (a, b).
  static const int kTets[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7},
                                  {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int z = 0; z + 1 < n.z(); ++z) {
    for (int y = 0; y + 1 < n.y(); ++y) {
      for (int x = 0; x + 1 < n.x(); ++x) {
        std::array<int64_t, 8> corner;
        bool any_in = false, any_out = false;
        for (int c = 0; c < 8; ++c) {
          corner[c] = grid_index(x + (c & 1), y + ((c >> 1) & 1), z + ((c >> 2) & 1));
          (values[corner[c]] < 0 ? any_in : any_out) = true;
        }
        if (!any_in || !any_out) continue;
        for (const auto& tet : kTets) {
          std::array<int64_t, 4> in, out;
          int num_in = 0, num_out = 0;
          for (int k = 0; k < 4; ++k) {
            const int64_t g = corner[tet[k]];
            if (values[g] < 0) {
              in[num_in++] = g;
            } else {
              out[num_out++] = g;
            }
          }
          if (num_in == 0 || num_out == 0) continue;
          Eigen::Vector3d in_c = Eigen::Vector3d::Zero(), out_c = Eigen::Vector3d::Zero();
          for (int k = 0; k < num_in; ++k) in_c += grid_point(in[k]) / num_in;
          for (int k = 0; k < num_out; ++k) out_c += grid_point(out[k]) / num_out;
          const Eigen::Vector3d outward = out_c - in_c;
          if (num_in == 1 || num_out == 1) {
            // One corner separated from three: one triangle.
            const bool single_in = num_in == 1;
            const int64_t s = single_in ? in[0] : out[0];
            const auto& others = single_in ? out : in;
            add_triangle(vertex_on_edge(s, others[0]), vertex_on_edge(s, others[1]),
                         vertex_on_edge(s, others[2]), outward);
          } else {
            // Two against two: a quad (in0-out0, in0-out1, in1-out1, in1-out0).
            const int a = vertex_on_edge(in[0], out[0]);
            const int b = vertex_on_edge(in[0], out[1]);
            const int c = vertex_on_edge(in[1], out[1]);
            const int d = vertex_on_edge(in[1], out[0]);
            add_triangle(a, b, c, outward);
            add_triangle(a, c, d, outward);
          }
        }
      }
    }
  }
  return mesh;
}

}  // namespace handlabel
