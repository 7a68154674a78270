#include "core/rasterizer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/mesh_primitives.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::Uniform;

Camera DistortedCamera() {
  // OPENCV: fx, fy, cx, cy, k1, k2, p1, p2 (noticeable barrel distortion).
  return Camera(CameraModelId::kOpenCV, 160, 120,
                {150.0, 152.0, 81.3, 58.7, -0.25, 0.08, 0.002, -0.001});
}

RenderMesh Triangle(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                    const Eigen::Vector3d& c) {
  RenderMesh m;
  m.vertices.resize(3, 3);
  m.vertices << a.transpose(), b.transpose(), c.transpose();
  m.faces.resize(1, 3);
  m.faces << 0, 1, 2;
  return m;
}

// Independent reference: does the ray through pixel (x, y) hit triangle abc (camera
// frame), and at which depth? Möller-Trumbore on the ray from the camera's own
// unprojection.
bool RayHitsTriangle(const Camera& camera, int x, int y, const Eigen::Vector3d& a,
                     const Eigen::Vector3d& b, const Eigen::Vector3d& c, double* z) {
  const Eigen::Vector3d d = camera.Unproject(Eigen::Vector2d(x, y));
  const Eigen::Vector3d e1 = b - a, e2 = c - a;
  const Eigen::Vector3d p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-15) return false;
  const Eigen::Vector3d s = -a;
  const double u = s.dot(p) / det;
  const Eigen::Vector3d qv = s.cross(e1);
  const double v = d.dot(qv) / det;
  const double t = e2.dot(qv) / det;
  if (u < 0 || v < 0 || u + v > 1 || t <= 0) return false;
  *z = t * d.z();
  return true;
}

void ExpectCoverageMatchesRayCasting(const Camera& camera) {
  const PixelRays rays(camera);
  int covered = 0;
  for (int trial = 0; trial < 20; ++trial) {
    // A random triangle of 5-30 pixels in front of the camera.
    const Eigen::Vector3d centre(Uniform(-0.15, 0.15), Uniform(-0.12, 0.12),
                                 Uniform(0.5, 1.0));
    const Eigen::Vector3d a = centre + testing::RandomVector3(-0.05, 0.05);
    const Eigen::Vector3d b = centre + testing::RandomVector3(-0.05, 0.05);
    const Eigen::Vector3d c = centre + testing::RandomVector3(-0.05, 0.05);
    VisibilityBuffer buffer;
    buffer.Reset(camera.width(), camera.height());
    RasterizeMesh(Triangle(a, b, c), 0, Rigid3(), rays, &buffer);
    int mismatched = 0;
    for (int y = 0; y < camera.height(); ++y) {
      for (int x = 0; x < camera.width(); ++x) {
        double z = 0;
        const bool hit = RayHitsTriangle(camera, x, y, a, b, c, &z);
        const size_t i = buffer.index(x, y);
        const bool drawn = buffer.mesh_id[i] == 0;
        if (hit != drawn) ++mismatched;
        if (hit && drawn) {
          ++covered;
          EXPECT_NEAR(buffer.depth[i], z, 1e-6 * z) << x << "," << y;
        }
      }
    }
    EXPECT_EQ(mismatched, 0) << "trial " << trial;
  }
  EXPECT_GT(covered, 200) << "the triangles must cover pixels";
}

// The visibility buffer (depth, ids, barycentrics) and the count of tested faces for
// two meshes seen by a pinhole and a distorted camera, including faces that leave the
// image, lie behind the near plane or fold under distortion: the same bits when drawn
// twice, and tests/data/reference/rasterizer_two_meshes.txt within 1e-9 relative to the
// buffer's sum (libm's variants move depths and barycentrics by ~1e-16; the ids and
// counts are compared exactly).
testing::ReferenceValues RasterizerValues() {
  const Camera pinhole(CameraModelId::kPinhole, 160, 120, {150.0, 152.0, 81.3, 58.7});
  testing::ReferenceValues values("rasterizer_two_meshes");
  const Eigen::Quaterniond box_rotation(0.42, -0.31, 0.77, 0.36);
  const Eigen::Quaterniond view_rotation(0.12, 0.58, -0.44, 0.67);
  for (const Camera& camera : {pinhole, DistortedCamera()}) {
    const std::string name = CameraModelName(camera.model());
    const PixelRays rays(camera);
    RenderMesh box = MakeBox(Eigen::Vector3d(0.5, 0.3, 0.4), 6);
    TransformMesh(Rigid3(box_rotation.normalized(), Eigen::Vector3d(0.2, 0.05, 0.25)),
                  &box);
    RenderMesh sphere = MakeSphere(0.1, 20, 30);
    TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.1, 0, 0.7)),
                  &sphere);
    const Rigid3 cam_from_world(
        view_rotation.normalized().slerp(0.95, Eigen::Quaterniond::Identity()),
        Eigen::Vector3d(0.01, -0.02, 0.03));
    VisibilityBuffer buffer;
    buffer.Reset(camera.width(), camera.height());
    values.Exact(name + ".box_faces",
                 RasterizeMesh(box, 0, cam_from_world, rays, &buffer));
    values.Exact(name + ".sphere_faces",
                 RasterizeMesh(sphere, 1, cam_from_world, rays, &buffer));
    values.Near(name + ".depth", buffer.depth).Exact(name + ".mesh_id", buffer.mesh_id);
    values.Exact(name + ".face_id", buffer.face_id).Near(name + ".bary", buffer.bary);
  }
  return values;
}

TEST(Rasterizer, SameSceneKeepsItsBuffer) {
  const testing::ReferenceValues first = RasterizerValues();
  EXPECT_EQ(first.Bits(), RasterizerValues().Bits());
  EXPECT_TRUE(first.Compare(0, 1e-9));
}

TEST(Rasterizer, TriangleCoverageAndDepthEqualRayCastingPinhole) {
  ExpectCoverageMatchesRayCasting(Camera::Pinhole(150, 150, 80, 60, 160, 120));
}

TEST(Rasterizer, TriangleCoverageAndDepthEqualRayCastingDistorted) {
  ExpectCoverageMatchesRayCasting(DistortedCamera());
}

TEST(Rasterizer, PointsProjectWhereCameraProjectSaysIncludingDistortion) {
  // A tiny triangle around a 3D point P: the pixel nearest to Project(P) must be the one
  // the rasteriser covers, and its depth must be P's.
  const Camera camera = DistortedCamera();
  const PixelRays rays(camera);
  for (int trial = 0; trial < 50; ++trial) {
    // Pick a pixel, then a point on its ray (exactly at the pixel centre).
    const int px = static_cast<int>(Uniform(5, 154)),
              py = static_cast<int>(Uniform(5, 114));
    const double z = Uniform(0.4, 1.2);
    const Eigen::Vector3d p = camera.Unproject(Eigen::Vector2d(px, py)) * z;
    Eigen::Vector2d uv;
    ASSERT_TRUE(camera.Project(p, &uv));
    EXPECT_NEAR(uv.x(), px, 1e-8);
    EXPECT_NEAR(uv.y(), py, 1e-8);
    // Triangle of ~0.3 px around p, facing the camera.
    const double s = 0.3 * z / camera.fx();
    const RenderMesh tri =
        Triangle(p + Eigen::Vector3d(-s, -s, 0), p + Eigen::Vector3d(s, -s, 0),
                 p + Eigen::Vector3d(0, s, 0));
    VisibilityBuffer buffer;
    buffer.Reset(camera.width(), camera.height());
    RasterizeMesh(tri, 3, Rigid3(), rays, &buffer);
    int count = 0;
    for (int y = 0; y < camera.height(); ++y) {
      for (int x = 0; x < camera.width(); ++x) {
        if (buffer.mesh_id[buffer.index(x, y)] == 3) {
          ++count;
          EXPECT_EQ(x, px);
          EXPECT_EQ(y, py);
          EXPECT_NEAR(buffer.depth[buffer.index(x, y)], z, 1e-6);
        }
      }
    }
    EXPECT_EQ(count, 1);
  }
}

TEST(Rasterizer, DepthOfATiltedPlaneIsTheRayPlaneIntersection) {
  const Camera camera = DistortedCamera();
  const PixelRays rays(camera);
  // A 4 m board, tilted, 0.8 m in front of a camera posed in the world.
  RenderMesh plane = MakePlane(Eigen::Vector2d(4.0, 4.0), 60, 60);
  const Rigid3 world_from_plane(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 0.3, 0).normalized())),
      Eigen::Vector3d(0.1, -0.2, 3.0));
  TransformMesh(world_from_plane, &plane);
  const Rigid3 cam_from_world(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0.0, 0.0, -2.2));
  VisibilityBuffer buffer;
  buffer.Reset(camera.width(), camera.height());
  RasterizeMesh(plane, 0, cam_from_world, rays, &buffer);
  const Rigid3 cam_from_plane = cam_from_world * world_from_plane;
  const Eigen::Vector3d normal = cam_from_plane.rotation * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d origin = cam_from_plane.translation;
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const size_t i = buffer.index(x, y);
      const Eigen::Vector3d d = camera.Unproject(Eigen::Vector2d(x, y));
      ASSERT_EQ(buffer.mesh_id[i], 0)
          << "the board fills the view " << x << "," << y << " "
          << (cam_from_plane.Inverse() * (d * (normal.dot(origin) / normal.dot(d))))
                 .transpose();
      const double z = normal.dot(origin) / normal.dot(d);  // t with d.z = 1
      EXPECT_NEAR(buffer.depth[i], z, 2e-6 * z);
    }
  }
}

TEST(Rasterizer, MaskIsExactlyTheVisiblePixelsOfEachMesh) {
  // A sphere in front of a box: the box mask is its own coverage minus the sphere's
  // nearer pixels; both masks are disjoint and match per-mesh renders.
  const Camera camera = DistortedCamera();
  const PixelRays rays(camera);
  RenderMesh sphere = MakeSphere(0.05);
  TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.02, 0, 0.5)),
                &sphere);
  RenderMesh box = MakeBox(Eigen::Vector3d(0.2, 0.15, 0.1), 6);
  TransformMesh(
      Rigid3(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())),
             Eigen::Vector3d(-0.03, 0.02, 0.7)),
      &box);
  VisibilityBuffer both, only_sphere, only_box;
  for (VisibilityBuffer* b : {&both, &only_sphere, &only_box}) {
    b->Reset(camera.width(), camera.height());
  }
  RasterizeMesh(box, 1, Rigid3(), rays, &both);
  RasterizeMesh(sphere, 0, Rigid3(), rays, &both);
  RasterizeMesh(sphere, 0, Rigid3(), rays, &only_sphere);
  RasterizeMesh(box, 1, Rigid3(), rays, &only_box);
  const ImageU8 sphere_mask = MaskOfMesh(both, 0);
  const ImageU8 box_mask = MaskOfMesh(both, 1);
  int sphere_pixels = 0, box_pixels = 0, hidden_box = 0;
  for (size_t i = 0; i < both.mesh_id.size(); ++i) {
    const bool s = only_sphere.mesh_id[i] == 0, b = only_box.mesh_id[i] == 1;
    const bool sphere_in_front = s && (!b || only_sphere.depth[i] < only_box.depth[i]);
    EXPECT_EQ(sphere_mask.data[i] == 255, sphere_in_front);
    EXPECT_EQ(box_mask.data[i] == 255, b && !sphere_in_front);
    EXPECT_EQ(both.depth[i], std::min(only_sphere.depth[i], only_box.depth[i]));
    sphere_pixels += sphere_in_front;
    box_pixels += box_mask.data[i] == 255;
    hidden_box += b && sphere_in_front;
  }
  EXPECT_GT(sphere_pixels, 500);
  EXPECT_GT(box_pixels, 500);
  EXPECT_GT(hidden_box, 300) << "the sphere must occlude part of the box";
}

TEST(Rasterizer, SphereSilhouetteMatchesTheAnalyticSphere) {
  // Pixels well inside the analytic silhouette are covered, pixels well outside are not
  // (tessellation error of a 64x96 sphere is < 0.2 % of the radius).
  const Camera camera = DistortedCamera();
  const PixelRays rays(camera);
  const Eigen::Vector3d c(0.03, -0.02, 0.6);
  const double radius = 0.08;
  RenderMesh sphere = MakeSphere(radius, 64, 96);
  TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), c), &sphere);
  VisibilityBuffer buffer;
  buffer.Reset(camera.width(), camera.height());
  RasterizeMesh(sphere, 0, Rigid3(), rays, &buffer);
  for (int y = 0; y < camera.height(); ++y) {
    for (int x = 0; x < camera.width(); ++x) {
      const Eigen::Vector3d d = camera.Unproject(Eigen::Vector2d(x, y)).normalized();
      const double dist = (c - c.dot(d) * d).norm();  // ray's distance to the centre
      const bool drawn = buffer.mesh_id[buffer.index(x, y)] == 0;
      if (dist < radius * 0.99) {
        EXPECT_TRUE(drawn);
        const double t = c.dot(d) - std::sqrt(radius * radius - dist * dist);
        EXPECT_NEAR(buffer.depth[buffer.index(x, y)], t * d.z(), 1e-3);
      }
      if (dist > radius * 1.01) {
        EXPECT_FALSE(drawn);
      }
    }
  }
}

TEST(Rasterizer, LambertShadingOfAPlane) {
  const Camera camera = Camera::Pinhole(100, 100, 32, 24, 64, 48);
  const PixelRays rays(camera);
  RenderMesh plane = MakePlane(Eigen::Vector2d(2, 2), 2, 2);
  plane.color = Eigen::Vector3f(0.5f, 0.25f, 1.0f);
  // Facing the camera (normal -z after the flip), 1 m away.
  TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1)), &plane);
  VisibilityBuffer buffer;
  buffer.Reset(64, 48);
  RasterizeMesh(plane, 0, Rigid3(), rays, &buffer);
  ShadingOptions shading;
  shading.ambient = Eigen::Vector3f(0.2f, 0.2f, 0.2f);
  DirectionalLight light;  // travels along +z, hits the plane at 60 degrees
  light.direction_in_world = Eigen::Vector3d(0, std::sin(M_PI / 3), 0.5);
  light.color = Eigen::Vector3f(0.6f, 0.6f, 0.6f);
  shading.lights = {light};
  ImageU8 rgb(64, 48, 3, 9);
  ShadeVisible({&plane}, buffer, Rigid3(), rays, shading, &rgb);
  const double factor = 0.2 + 0.6 * 0.5;  // cos 60 = 0.5
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      EXPECT_NEAR(rgb.at(x, y, 0), 255 * 0.5 * factor, 0.51);
      EXPECT_NEAR(rgb.at(x, y, 1), 255 * 0.25 * factor, 0.51);
      EXPECT_NEAR(rgb.at(x, y, 2), 255 * 1.0 * factor, 0.51);
    }
  }
}

// The cache hands out one PixelRays per distinct camera, equal to a fresh one.
TEST(Rasterizer, PixelRaysCacheBuildsOncePerCamera) {
  PixelRaysCache cache;
  const Camera distorted = DistortedCamera();
  Camera other = distorted;
  other.mutable_params()[0] += 0.5;  // another focal length: another camera
  const std::shared_ptr<const PixelRays> a = cache.Get(distorted);
  EXPECT_EQ(cache.Get(distorted), a);
  const std::shared_ptr<const PixelRays> b = cache.Get(other);
  EXPECT_NE(b, a);
  const PixelRays fresh(other);
  for (int y : {0, 60, 119}) {
    for (int x : {0, 80, 159}) {
      EXPECT_EQ(b->xy(x, y)[0], fresh.xy(x, y)[0]);
      EXPECT_EQ(b->xy(x, y)[1], fresh.xy(x, y)[1]);
    }
  }
  EXPECT_NE(a->xy(0, 0)[0], b->xy(0, 0)[0]);
}

TEST(Rasterizer, BackgroundPixelsAreLeftAlone) {
  const Camera camera = Camera::Pinhole(100, 100, 32, 24, 64, 48);
  const PixelRays rays(camera);
  VisibilityBuffer buffer;
  buffer.Reset(64, 48);
  RenderMesh sphere = MakeSphere(0.01);
  TransformMesh(Rigid3(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0, 1)),
                &sphere);
  RasterizeMesh(sphere, 0, Rigid3(), rays, &buffer);
  ImageU8 rgb(64, 48, 3, 77);
  ShadeVisible({&sphere}, buffer, Rigid3(), rays, ShadingOptions(), &rgb);
  EXPECT_EQ(rgb.at(0, 0, 0), 77);
  EXPECT_EQ(rgb.at(63, 47, 2), 77);
  EXPECT_EQ(buffer.mesh_id[buffer.index(0, 0)], -1);
  EXPECT_TRUE(std::isinf(buffer.depth[buffer.index(0, 0)]));
}

}  // namespace
}  // namespace handlabel

namespace handlabel {
namespace {

TEST(Rasterizer, TexturesAreSampledAtThePerspectiveCorrectUv) {
  // An 8x8 texture of four coloured quadrants on a tilted plane: each pixel's colour
  // must be the quadrant's at the uv of the point its ray hits (computed independently
  // by ray-plane intersection).
  const Camera camera = Camera::Pinhole(120, 120, 40, 30, 80, 60);
  const PixelRays rays(camera);
  RenderMesh plane = MakePlane(Eigen::Vector2d(1.0, 1.0), 1, 1);  // two triangles
  auto tex = std::make_shared<ImageU8>(8, 8, 3);
  const uint8_t colours[4][3] = {{200, 0, 0}, {0, 200, 0}, {0, 0, 200}, {200, 200, 0}};
  for (int y = 0; y < 8; ++y)
    for (int x = 0; x < 8; ++x)
      for (int c = 0; c < 3; ++c) tex->at(x, y, c) = colours[x / 4 + 2 * (y / 4)][c];
  plane.texture = tex;
  plane.color = Eigen::Vector3f::Ones();
  const Rigid3 world_from_plane(
      Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitY())),
      Eigen::Vector3d(0, 0, 1.2));
  TransformMesh(world_from_plane, &plane);
  VisibilityBuffer buffer;
  buffer.Reset(80, 60);
  RasterizeMesh(plane, 0, Rigid3(), rays, &buffer);
  ShadingOptions flat;
  flat.ambient = Eigen::Vector3f::Ones();  // colour = albedo
  flat.lights.clear();
  ImageU8 rgb(80, 60, 3);
  ShadeVisible({&plane}, buffer, Rigid3(), rays, flat, &rgb);
  const Rigid3 plane_from_world = world_from_plane.Inverse();
  int checked = 0;
  for (int y = 0; y < 60; ++y) {
    for (int x = 0; x < 80; ++x) {
      if (buffer.mesh_id[buffer.index(x, y)] != 0) continue;
      // Hit point in plane coordinates -> uv in [0, 1].
      const Eigen::Vector3d d = camera.Unproject(Eigen::Vector2d(x, y));
      const Eigen::Vector3d o = plane_from_world.translation;
      const Eigen::Vector3d dp = plane_from_world.rotation * d;
      const Eigen::Vector3d hit = o - (o.z() / dp.z()) * dp;
      const double u = hit.x() + 0.5, v = hit.y() + 0.5;
      // Bilinear filtering blends within half a texel (1/16) of a quadrant border
      // (the texture wraps, so also at 0 and 1); skip those.
      auto inside = [](double t) {
        return (t > 0.07 && t < 0.43) || (t > 0.57 && t < 0.93);
      };
      if (!inside(u) || !inside(v)) continue;
      const int texel = (u > 0.5 ? 1 : 0) + 2 * (v > 0.5 ? 1 : 0);
      for (int c = 0; c < 3; ++c) EXPECT_NEAR(rgb.at(x, y, c), colours[texel][c], 1);
      ++checked;
    }
  }
  EXPECT_GT(checked, 50);
}

}  // namespace
}  // namespace handlabel
