// Implicit mesher, decimation, mesh checks and NNLS on problems with known answers.
#include <gtest/gtest.h>

#include <cmath>

#include "core/point_arrays.h"
#include "openhand/implicit_mesher.h"
#include "openhand/mesh_checks.h"
#include "openhand/mesh_decimation.h"
#include "openhand/nnls.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

void ToArrays(const TriangleMesh& mesh, Points3d* v, Faces* f) {
  v->resize(static_cast<Eigen::Index>(mesh.vertices.size()), 3);
  for (size_t i = 0; i < mesh.vertices.size(); ++i) v->row(i) = mesh.vertices[i];
  f->resize(static_cast<Eigen::Index>(mesh.faces.size()), 3);
  for (size_t i = 0; i < mesh.faces.size(); ++i) f->row(i) = mesh.faces[i];
}

TriangleMesh Sphere(double radius, double step) {
  ImplicitMesherOptions options;
  options.step = step;
  const Eigen::Vector3d c(0.0013, -0.0007, 0.0021);  // off-grid centre
  return MeshImplicitSurface(
      [&](const Eigen::Vector3d& p) { return (p - c).norm() - radius; },
      Eigen::Vector3d::Constant(-0.03), Eigen::Vector3d::Constant(0.03), options);
}

TEST(ImplicitMesher, SphereIsClosedOutwardAndHasTheRightVolume) {
  const double r = 0.02;
  const TriangleMesh mesh = Sphere(r, 0.0015);
  Points3d v;
  Faces f;
  ToArrays(mesh, &v, &f);
  const MeshTopology topo = AnalyzeMeshTopology(static_cast<int>(v.rows()), f);
  EXPECT_TRUE(topo.IsClosedManifold())
      << "boundary " << topo.boundary_edges << " nonmanifold " << topo.nonmanifold_edges
      << " misoriented " << topo.misoriented_edges << " euler "
      << topo.euler_characteristic;
  const double exact = 4.0 / 3.0 * M_PI * r * r * r;
  EXPECT_NEAR(SignedVolume(v, f), exact, 0.01 * exact);
  for (const auto& p : mesh.vertices)
    EXPECT_NEAR((p - Eigen::Vector3d(0.0013, -0.0007, 0.0021)).norm(), r, 2e-4);
}

// A torus's vertices and faces (the grid does not divide the box, so the last samples
// lie beyond `hi`): the same bits when meshed twice, and
// tests/data/reference/implicit_mesher_torus.txt (faces exactly, vertices within 1e-12
// m: the field's hypot comes from libm, ~1e-16 relative between its variants).
testing::ReferenceValues TorusValues() {
  ImplicitMesherOptions options;
  options.step = 0.0023;
  const TriangleMesh mesh = MeshImplicitSurface(
      [](const Eigen::Vector3d& p) {
        const double ring = std::hypot(p.x(), p.y()) - 0.02;
        return std::hypot(ring, p.z()) - 0.008;
      },
      Eigen::Vector3d(-0.031, -0.03, -0.012), Eigen::Vector3d(0.03, 0.032, 0.011),
      options);
  Points3d v;
  Faces f;
  ToArrays(mesh, &v, &f);
  testing::ReferenceValues values("implicit_mesher_torus");
  values.Near("vertices", v);
  values.Exact("faces", std::vector<int>(f.data(), f.data() + f.size()));
  return values;
}

TEST(ImplicitMesher, SameFieldKeepsItsMesh) {
  const testing::ReferenceValues first = TorusValues();
  EXPECT_EQ(first.Bits(), TorusValues().Bits());
  EXPECT_TRUE(first.Compare(1e-12, 0));
}

TEST(MeshDecimation, KeepsASphereClosedAndRound) {
  const TriangleMesh fine = Sphere(0.02, 0.0015);
  DecimationOptions options;
  options.target_vertices = 300;
  TriangleMesh coarse = DecimateMesh(fine, options);
  EXPECT_EQ(static_cast<int>(coarse.vertices.size()), 300);
  const Eigen::Vector3d c(0.0013, -0.0007, 0.0021);
  RelaxMesh(&coarse, 3, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    return c + 0.02 * (p - c).normalized();
  });
  Points3d v;
  Faces f;
  ToArrays(coarse, &v, &f);
  EXPECT_TRUE(AnalyzeMeshTopology(static_cast<int>(v.rows()), f).IsClosedManifold());
  EXPECT_EQ(CountSelfIntersections(v, f), 0);
  const double exact = 4.0 / 3.0 * M_PI * 0.02 * 0.02 * 0.02;
  EXPECT_NEAR(SignedVolume(v, f), exact, 0.03 * exact);
}

// Mean over faces of each face's smallest angle (degrees).
double MeanMinAngleDeg(const TriangleMesh& mesh) {
  double sum = 0.0;
  for (const Eigen::Vector3i& f : mesh.faces) {
    double smallest = 180.0;
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d u =
          (mesh.vertices[f[(k + 1) % 3]] - mesh.vertices[f[k]]).normalized();
      const Eigen::Vector3d w =
          (mesh.vertices[f[(k + 2) % 3]] - mesh.vertices[f[k]]).normalized();
      smallest = std::min(smallest, std::acos(u.dot(w)) * 180.0 / M_PI);
    }
    sum += smallest;
  }
  return sum / static_cast<double>(mesh.faces.size());
}

TEST(MeshDecimation, EdgeFlipsRaiseTheMinimumAnglesAndKeepTheMeshClosed) {
  const TriangleMesh fine = Sphere(0.02, 0.0015);
  DecimationOptions options;
  options.target_vertices = 300;
  const TriangleMesh plain = DecimateMesh(fine, options);
  options.improve_by_flips = true;
  const TriangleMesh flipped = DecimateMesh(fine, options);
  EXPECT_EQ(flipped.vertices, plain.vertices);  // flips move no vertex
  EXPECT_GT(MeanMinAngleDeg(flipped), MeanMinAngleDeg(plain) + 0.5);
  Points3d v;
  Faces f;
  ToArrays(flipped, &v, &f);
  EXPECT_TRUE(AnalyzeMeshTopology(static_cast<int>(v.rows()), f).IsClosedManifold());
  EXPECT_EQ(CountSelfIntersections(v, f), 0);
}

TEST(MeshChecks, DetectsOpenFlippedAndIntersectingMeshes) {
  // A tetrahedron, outward.
  Points3d v(4, 3);
  v << 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1;
  Faces f(4, 3);
  f << 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3;
  EXPECT_TRUE(AnalyzeMeshTopology(4, f).IsClosedManifold());
  EXPECT_NEAR(SignedVolume(v, f), 1.0 / 6.0, 1e-12);
  Faces flipped = f;
  flipped.row(0) << 0, 1, 2;
  EXPECT_EQ(AnalyzeMeshTopology(4, flipped).misoriented_edges, 3);
  EXPECT_EQ(AnalyzeMeshTopology(4, f.topRows(3)).boundary_edges, 3);
  EXPECT_EQ(CountSelfIntersections(v, f), 0);
  // Two triangles crossing each other, sharing no vertex.
  Points3d w(6, 3);
  w << -1, 0, 0, 1, 0, 0, 0, 1, 0,  //
      0, 0.5, -1, 0, 0.5, 1, 0, -1, 0;
  Faces g(2, 3);
  g << 0, 1, 2, 3, 4, 5;
  EXPECT_EQ(CountSelfIntersections(w, g), 1);
  // Moved aside: the second triangle now passes beside the first.
  w.row(5) << 0, 0.8, 0.5;
  w.row(3) << 5, 0.5, -1;
  w.row(4) << 5, 0.5, 1;
  EXPECT_EQ(CountSelfIntersections(w, g), 0);
}

TEST(Nnls, MatchesAKnownSolutionAndStaysNonNegative) {
  // Exact non-negative solution is recovered.
  Eigen::MatrixXd a = Eigen::MatrixXd::Random(20, 6);
  Eigen::VectorXd x_true(6);
  x_true << 0.5, 0, 1.2, 0, 0.3, 2.0;
  Eigen::VectorXd x = SolveNnls(a, a * x_true);
  EXPECT_LT((x - x_true).norm(), 1e-9);
  // Unconstrained optimum with negative entries: result is >= 0 and satisfies KKT
  // (gradient >= 0 on the zero set, ~0 on the positive set).
  const Eigen::VectorXd b = Eigen::VectorXd::Random(20);
  x = SolveNnls(a, b);
  const Eigen::VectorXd grad = a.transpose() * (a * x - b);
  for (int i = 0; i < 6; ++i) {
    EXPECT_GE(x[i], 0.0);
    if (x[i] > 0)
      EXPECT_NEAR(grad[i], 0.0, 1e-9);
    else
      EXPECT_GE(grad[i], -1e-9);
  }
}

}  // namespace
}  // namespace handlabel
