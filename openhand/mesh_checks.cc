#include "openhand/mesh_checks.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <map>
#include <numeric>

#include "core/point_arrays.h"
#include "geometry/axis_angle.h"

namespace handlabel {
namespace {

int Find(std::vector<int>& parent, int i) {
  while (parent[i] != i) i = parent[i] = parent[parent[i]];
  return i;
}

// Möller-Trumbore: does the segment p -> q cross triangle (a, b, c)?
bool SegmentHitsTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& q,
                         const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                         const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-18) return false;
  const Eigen::Vector3d s = p - a;
  const double u = s.dot(h) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = d.dot(qv) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = e2.dot(qv) / det;
  return t >= 0 && t <= 1;
}

}  // namespace

bool MeshTopology::IsClosedManifold() const {
  return boundary_edges == 0 && nonmanifold_edges == 0 && misoriented_edges == 0 &&
         nonmanifold_vertices == 0 && unused_vertices == 0 && degenerate_faces == 0 &&
         components == 1 && euler_characteristic == 2;
}

MeshTopology AnalyzeMeshTopology(int num_vertices, const Faces& faces) {
  MeshTopology t;
  t.num_vertices = num_vertices;
  t.num_faces = static_cast<int>(faces.rows());
  // Directed edge counts per undirected edge.
  std::map<std::pair<int, int>, std::pair<int, int>>
      edges;  // (lo, hi) -> (lo->hi, hi->lo)
  std::vector<int> used(num_vertices, 0);
  std::vector<int> parent(t.num_faces);
  std::iota(parent.begin(), parent.end(), 0);
  std::map<std::pair<int, int>, int> first_face;
  for (int f = 0; f < t.num_faces; ++f) {
    const int a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
    if (a == b || b == c || a == c) ++t.degenerate_faces;
    for (int k = 0; k < 3; ++k) {
      const int u = faces(f, k), v = faces(f, (k + 1) % 3);
      ++used[u];
      auto& e = edges[{std::min(u, v), std::max(u, v)}];
      (u < v ? e.first : e.second)++;
      auto [it, fresh] =
          first_face.emplace(std::make_pair(std::min(u, v), std::max(u, v)), f);
      if (!fresh) parent[Find(parent, f)] = Find(parent, it->second);
    }
  }
  t.num_edges = static_cast<int>(edges.size());
  for (const auto& [key, count] : edges) {
    const int n = count.first + count.second;
    if (n == 1) ++t.boundary_edges;
    if (n > 2) ++t.nonmanifold_edges;
    if (n == 2 && count.first != 1) ++t.misoriented_edges;
  }
  for (int v = 0; v < num_vertices; ++v)
    if (used[v] == 0) ++t.unused_vertices;
  for (int f = 0; f < t.num_faces; ++f)
    if (Find(parent, f) == f) ++t.components;
  // A vertex is manifold when its faces form one fan: walk the fan via shared edges.
  std::vector<std::vector<int>> vertex_faces(num_vertices);
  for (int f = 0; f < t.num_faces; ++f)
    for (int k = 0; k < 3; ++k) vertex_faces[faces(f, k)].push_back(f);
  for (int v = 0; v < num_vertices; ++v) {
    const auto& vf = vertex_faces[v];
    if (vf.empty()) continue;
    // Union faces around v that share an edge (v, w).
    std::map<int, int> local;
    for (size_t i = 0; i < vf.size(); ++i) local[vf[i]] = static_cast<int>(i);
    std::vector<int> p(vf.size());
    std::iota(p.begin(), p.end(), 0);
    std::map<int, int> other_vertex_face;
    for (size_t i = 0; i < vf.size(); ++i) {
      for (int k = 0; k < 3; ++k) {
        const int w = faces(vf[i], k);
        if (w == v) continue;
        auto [it, fresh] = other_vertex_face.emplace(w, static_cast<int>(i));
        if (!fresh) p[Find(p, static_cast<int>(i))] = Find(p, it->second);
      }
    }
    int fans = 0;
    for (size_t i = 0; i < vf.size(); ++i)
      if (Find(p, static_cast<int>(i)) == static_cast<int>(i)) ++fans;
    if (fans > 1) ++t.nonmanifold_vertices;
  }
  t.euler_characteristic = num_vertices - t.unused_vertices - t.num_edges + t.num_faces;
  return t;
}

double SignedVolume(const Points3d& v, const Faces& faces) {
  double vol = 0.0;
  for (Eigen::Index f = 0; f < faces.rows(); ++f) {
    const Eigen::Vector3d a = v.row(faces(f, 0)), b = v.row(faces(f, 1)),
                          c = v.row(faces(f, 2));
    vol += a.dot(b.cross(c)) / 6.0;
  }
  return vol;
}

int CountSelfIntersections(const Points3d& v, const Faces& faces) {
  return static_cast<int>(SelfIntersectingFacePairs(v, faces).size());
}

std::vector<std::pair<int, int>> SelfIntersectingFacePairs(const Points3d& v,
                                                           const Faces& faces) {
  const Eigen::Index nf = faces.rows();
  std::vector<Eigen::AlignedBox3d> boxes(nf);
  for (Eigen::Index f = 0; f < nf; ++f)
    for (int k = 0; k < 3; ++k) boxes[f].extend(Eigen::Vector3d(v.row(faces(f, k))));
  std::vector<std::pair<int, int>> pairs;
  for (Eigen::Index f = 0; f < nf; ++f) {
    for (Eigen::Index g = f + 1; g < nf; ++g) {
      if (!boxes[f].intersects(boxes[g])) continue;
      bool shared = false;
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) shared |= faces(f, i) == faces(g, k);
      if (shared) continue;
      bool hit = false;
      for (int pass = 0; pass < 2 && !hit; ++pass) {
        const Eigen::Index s = pass == 0 ? f : g, t = pass == 0 ? g : f;
        const Eigen::Vector3d a = v.row(faces(t, 0)), b = v.row(faces(t, 1)),
                              c = v.row(faces(t, 2));
        for (int k = 0; k < 3 && !hit; ++k) {
          hit = SegmentHitsTriangle(v.row(faces(s, k)), v.row(faces(s, (k + 1) % 3)), a,
                                    b, c);
        }
      }
      if (hit) pairs.emplace_back(static_cast<int>(f), static_cast<int>(g));
    }
  }
  return pairs;
}

std::vector<Eigen::Matrix3d> GlobalJointRotations(const HandModel& model,
                                                  const HandParams& params) {
  std::vector<Eigen::Matrix3d> global(kNumHandJoints);
  for (int j = 0; j < kNumHandJoints; ++j) {
    const double* aa =
        j == 0 ? params.global_orient.data() : params.hand_pose.data() + 3 * (j - 1);
    double r[9];
    AxisAngleToRotation(aa, r);
    const Eigen::Matrix3d local =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(r);
    global[j] = j == 0 ? local : Eigen::Matrix3d(global[model.parents[j]] * local);
  }
  return global;
}

double InvertedFaceFraction(const HandModel& model, const HandParams& params) {
  const HandMesh posed = PoseHand(model, params);
  HandParams rest_params;
  rest_params.betas = params.betas;
  const HandMesh rest = PoseHand(model, rest_params);
  const std::vector<Eigen::Matrix3d> global = GlobalJointRotations(model, params);
  int inverted = 0;
  for (int f = 0; f < model.num_faces(); ++f) {
    Eigen::Matrix<double, 1, kNumHandJoints> w =
        Eigen::Matrix<double, 1, kNumHandJoints>::Zero();
    for (int k = 0; k < 3; ++k) w += model.skinning_weights.row(model.faces(f, k));
    Eigen::Index dominant;
    w.maxCoeff(&dominant);
    auto normal = [&](const Points3d& p) {
      const Eigen::Vector3d a = p.row(model.faces(f, 0)), b = p.row(model.faces(f, 1)),
                            c = p.row(model.faces(f, 2));
      return Eigen::Vector3d((b - a).cross(c - a));
    };
    if (normal(posed.vertices).dot(global[dominant] * normal(rest.vertices)) < 0)
      ++inverted;
  }
  return model.num_faces() > 0 ? static_cast<double>(inverted) / model.num_faces() : 0.0;
}

}  // namespace handlabel
