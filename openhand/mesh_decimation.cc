#include "openhand/mesh_decimation.h"

#include <Eigen/Geometry>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Decimater/DecimaterT.hh>
#include <OpenMesh/Tools/Decimater/ModAspectRatioT.hh>
#include <OpenMesh/Tools/Decimater/ModNormalFlippingT.hh>
#include <OpenMesh/Tools/Decimater/ModQuadricT.hh>
#include <algorithm>

#include "core/errors.h"
#include "core/option_checks.h"

namespace handlabel {
namespace {

struct DoubleTraits : public OpenMesh::DefaultTraits {
  typedef OpenMesh::Vec3d Point;
  typedef OpenMesh::Vec3d Normal;
};
using OMesh = OpenMesh::TriMesh_ArrayKernelT<DoubleTraits>;

double MinAngle(const OMesh::Point& a, const OMesh::Point& b, const OMesh::Point& c) {
  auto angle = [](const OMesh::Point& p, const OMesh::Point& q, const OMesh::Point& r) {
    const OMesh::Point u = (q - p).normalized(), v = (r - p).normalized();
    return std::acos(std::clamp(u.dot(v), -1.0, 1.0));
  };
  return std::min({angle(a, b, c), angle(b, c, a), angle(c, a, b)});
}

// Flips edges between nearly coplanar triangles when that raises the smaller of their
// minimum angles (towards a Delaunay triangulation); the shape barely changes.
void ImproveByFlips(OMesh* om) {
  const double kMaxDihedral = 20.0 * M_PI / 180.0;
  for (int sweep = 0; sweep < 10; ++sweep) {
    int flips = 0;
    for (const auto eh : om->edges()) {
      if (!om->is_flip_ok(eh)) continue;
      const auto h0 = om->halfedge_handle(eh, 0), h1 = om->halfedge_handle(eh, 1);
      const OMesh::Point a = om->point(om->to_vertex_handle(h0));
      const OMesh::Point b = om->point(om->to_vertex_handle(h1));
      const OMesh::Point c =
          om->point(om->to_vertex_handle(om->next_halfedge_handle(h0)));
      const OMesh::Point d =
          om->point(om->to_vertex_handle(om->next_halfedge_handle(h1)));
      // Faces (b, a, c) and (a, b, d) now; (c, d, a) and (d, c, b) after the flip.
      const OMesh::Point n0 = (a - b).cross(c - b).normalized();
      const OMesh::Point n1 = (b - a).cross(d - a).normalized();
      if (std::acos(std::clamp(n0.dot(n1), -1.0, 1.0)) > kMaxDihedral) continue;
      const OMesh::Point m0 = (d - c).cross(a - c), m1 = (c - d).cross(b - d);
      if (m0.dot(n0) <= 0 || m1.dot(n0) <= 0) continue;  // would fold over
      const double before = std::min(MinAngle(b, a, c), MinAngle(a, b, d));
      const double after = std::min(MinAngle(c, d, a), MinAngle(d, c, b));
      if (after > before + 1e-3) {
        om->flip(eh);
        ++flips;
      }
    }
    if (flips == 0) break;
  }
}

}  // namespace

void DecimationOptions::Check(const std::string& source) const {
  RequireAtLeast(source, "target_vertices", target_vertices, 4, "at least 4");
  // Open below, so not RequireInRange.
  if (!(max_normal_deviation_deg > 0.0 && max_normal_deviation_deg <= 180.0)) {
    throw InputError(source, "max_normal_deviation_deg", "(0, 180]",
                     OptionValueText(max_normal_deviation_deg));
  }
  RequireAtLeast(source, "min_aspect_ratio", min_aspect_ratio, 0);
}

TriangleMesh DecimateMesh(const TriangleMesh& mesh, const DecimationOptions& options) {
  options.Check("decimation options");
  OMesh om;
  std::vector<OMesh::VertexHandle> handles;
  handles.reserve(mesh.vertices.size());
  for (const Eigen::Vector3d& v : mesh.vertices) {
    handles.push_back(om.add_vertex(OMesh::Point(v.x(), v.y(), v.z())));
  }
  for (const Eigen::Vector3i& f : mesh.faces) {
    const auto fh = om.add_face(handles[f[0]], handles[f[1]], handles[f[2]]);
    HL_CHECK(fh.is_valid(), "decimation input must be a manifold mesh");
  }
  om.request_vertex_status();
  om.request_edge_status();
  om.request_face_status();
  om.request_face_normals();
  om.update_face_normals();

  OpenMesh::Decimater::DecimaterT<OMesh> decimater(om);
  OpenMesh::Decimater::ModQuadricT<OMesh>::Handle quadric;
  OpenMesh::Decimater::ModNormalFlippingT<OMesh>::Handle flipping;
  OpenMesh::Decimater::ModAspectRatioT<OMesh>::Handle aspect;
  decimater.add(quadric);
  decimater.module(quadric).unset_max_err();
  decimater.add(flipping);
  decimater.module(flipping).set_max_normal_deviation(options.max_normal_deviation_deg);
  if (options.min_aspect_ratio > 0.0) {
    decimater.add(aspect);
    decimater.module(aspect).set_aspect_ratio(
        static_cast<float>(options.min_aspect_ratio));
  }
  HL_CHECK(decimater.initialize(), "OpenMesh decimater did not initialise");
  decimater.decimate_to(static_cast<size_t>(options.target_vertices));
  om.garbage_collection();
  if (options.improve_by_flips) ImproveByFlips(&om);

  TriangleMesh out;
  out.vertices.reserve(om.n_vertices());
  for (const auto vh : om.vertices()) {
    const OMesh::Point& p = om.point(vh);
    out.vertices.emplace_back(p[0], p[1], p[2]);
  }
  for (const auto fh : om.faces()) {
    Eigen::Vector3i f;
    int k = 0;
    for (const auto vh : om.fv_range(fh)) f[k++] = vh.idx();
    out.faces.push_back(f);
  }
  return out;
}

std::vector<std::vector<int>> VertexNeighbours(const TriangleMesh& mesh) {
  std::vector<std::vector<int>> nb(mesh.vertices.size());
  for (const Eigen::Vector3i& f : mesh.faces) {
    for (int k = 0; k < 3; ++k) {
      nb[f[k]].push_back(f[(k + 1) % 3]);
      nb[f[k]].push_back(f[(k + 2) % 3]);
    }
  }
  for (auto& n : nb) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
  }
  return nb;
}

std::vector<Eigen::Vector3d> VertexNormals(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3d> n(mesh.vertices.size(), Eigen::Vector3d::Zero());
  for (const Eigen::Vector3i& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.vertices[f[0]], b = mesh.vertices[f[1]],
                          c = mesh.vertices[f[2]];
    const Eigen::Vector3d fn = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n[f[k]] += fn;
  }
  for (auto& v : n) {
    const double len = v.norm();
    if (len > 0) v /= len;
  }
  return n;
}

void RelaxMesh(TriangleMesh* mesh, int iterations,
               const std::function<Eigen::Vector3d(const Eigen::Vector3d&)>& project) {
  const std::vector<std::vector<int>> nb = VertexNeighbours(*mesh);
  for (int it = 0; it < iterations; ++it) {
    const std::vector<Eigen::Vector3d> normals = VertexNormals(*mesh);
    std::vector<Eigen::Vector3d> next = mesh->vertices;
    for (size_t v = 0; v < next.size(); ++v) {
      if (nb[v].empty()) continue;
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (int u : nb[v]) c += mesh->vertices[u];
      c /= static_cast<double>(nb[v].size());
      Eigen::Vector3d step = c - mesh->vertices[v];
      step -= step.dot(normals[v]) * normals[v];
      next[v] = project(mesh->vertices[v] + 0.5 * step);
    }
    mesh->vertices = std::move(next);
  }
}

}  // namespace handlabel
