#pragma once
// Random rigs and COLMAP models for the calib tests.
#include <string>

#include "cameras/colmap_model.h"
#include "geometry/rig.h"
#include "tests/test_util.h"

namespace handlabel::testing {

// Plausible parameters for a model: focal ~500, centre near the image centre, small
// distortion.
inline std::vector<double> RandomParams(CameraModelId model, int width, int height) {
  const double f = Uniform(300, 900), cx = width / 2.0 + Uniform(-20, 20),
               cy = height / 2.0 + Uniform(-20, 20);
  std::vector<double> p;
  switch (model) {
    case CameraModelId::kSimplePinhole:
      return {f, cx, cy};
    case CameraModelId::kSimpleRadial:
      return {f, cx, cy, Uniform(-0.2, 0.2)};
    case CameraModelId::kRadial:
      return {f, cx, cy, Uniform(-0.2, 0.2), Uniform(-0.05, 0.05)};
    default:
      p = {f, f * Uniform(0.98, 1.02), cx, cy};
  }
  for (int i = 4; i < NumCameraParams(model); ++i) p.push_back(Uniform(-0.05, 0.05));
  return p;
}

inline Rig RandomRig(int num_cameras) {
  Rig rig;
  for (int i = 0; i < num_cameras; ++i) {
    RigCamera c;
    c.name = "cam" + std::to_string(i);
    const CameraModelId model = static_cast<CameraModelId>(i % 7);
    const int width = 640 + 16 * i, height = 480;
    c.camera = Camera(model, width, height, RandomParams(model, width, height));
    c.cam_from_world = Rigid3(RandomRotation(), RandomVector3(-2, 2));
    rig.Add(c);
  }
  return rig;
}

// Cameras of every model, images with non-contiguous ids, points with tracks.
inline ColmapModel RandomColmapModel() {
  ColmapModel model;
  for (int m = 0; m < 7; ++m) {
    ColmapCamera cam;
    cam.id = 3 + 5 * m;
    cam.model = static_cast<CameraModelId>(m);
    cam.width = 640 + m;
    cam.height = 480 + 2 * m;
    cam.params = RandomParams(cam.model, 640, 480);
    model.cameras[cam.id] = cam;
  }
  std::vector<uint32_t> camera_ids;
  for (const auto& [id, cam] : model.cameras) camera_ids.push_back(id);
  for (int i = 0; i < 9; ++i) {
    ColmapImage image;
    image.id = 10 + 7 * i;
    image.camera_id = camera_ids[i % camera_ids.size()];
    image.name = "cam" + std::to_string(i) + "/frame_000" + std::to_string(i) + ".png";
    image.cam_from_world = Rigid3(RandomRotation(), RandomVector3(-3, 3));
    model.images[image.id] = image;
  }
  uint64_t next_point = 100;
  for (int p = 0; p < 40; ++p) {
    ColmapPoint3D point;
    point.id = next_point;
    next_point += 1 + p % 3;
    point.xyz = RandomVector3(-5, 5);
    point.rgb = {static_cast<uint8_t>(p * 5), static_cast<uint8_t>(255 - p),
                 static_cast<uint8_t>(p % 7)};
    point.error = Uniform(0, 2);
    for (auto& [id, image] : model.images) {
      if (Uniform(0, 1) < 0.5) continue;
      point.track.push_back({id, static_cast<uint32_t>(image.points2D.size())});
      image.points2D.emplace_back(Uniform(0, 640), Uniform(0, 480));
      image.point3D_ids.push_back(point.id);
    }
    model.points3D[point.id] = point;
  }
  // Some observations without a 3D point.
  for (auto& [id, image] : model.images) {
    image.points2D.emplace_back(Uniform(0, 640), Uniform(0, 480));
    image.point3D_ids.push_back(kColmapNoPoint3D);
  }
  return model;
}

// Every value equal; quaternions within `quat_tol` (readers re-normalise).
inline void ExpectModelsEqual(const ColmapModel& a, const ColmapModel& b,
                              double quat_tol = 1e-15) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  for (const auto& [id, cam] : a.cameras) {
    ASSERT_TRUE(b.cameras.count(id)) << "camera " << id;
    const ColmapCamera& other = b.cameras.at(id);
    EXPECT_EQ(cam.model, other.model) << "camera " << id;
    EXPECT_EQ(cam.width, other.width) << "camera " << id;
    EXPECT_EQ(cam.height, other.height) << "camera " << id;
    EXPECT_EQ(cam.params, other.params) << "camera " << id;
  }
  ASSERT_EQ(a.images.size(), b.images.size());
  for (const auto& [id, image] : a.images) {
    ASSERT_TRUE(b.images.count(id)) << "image " << id;
    const ColmapImage& other = b.images.at(id);
    EXPECT_THAT(
        Eigen::Vector4d(image.cam_from_world.rotation.coeffs()),
        MatrixNear(Eigen::Vector4d(other.cam_from_world.rotation.coeffs()), quat_tol))
        << "image " << id;
    EXPECT_EQ(image.cam_from_world.translation, other.cam_from_world.translation)
        << "image " << id;
    EXPECT_EQ(image.camera_id, other.camera_id);
    EXPECT_EQ(image.name, other.name);
    EXPECT_EQ(image.points2D, other.points2D) << "image " << id;
    EXPECT_EQ(image.point3D_ids, other.point3D_ids) << "image " << id;
  }
  ASSERT_EQ(a.points3D.size(), b.points3D.size());
  for (const auto& [id, p] : a.points3D) {
    ASSERT_TRUE(b.points3D.count(id)) << "point " << id;
    const ColmapPoint3D& other = b.points3D.at(id);
    EXPECT_EQ(p.xyz, other.xyz) << "point " << id;
    EXPECT_EQ(p.rgb, other.rgb) << "point " << id;
    EXPECT_EQ(p.error, other.error) << "point " << id;
    ASSERT_EQ(p.track.size(), other.track.size()) << "point " << id;
    for (size_t k = 0; k < p.track.size(); ++k) {
      EXPECT_EQ(p.track[k].image_id, other.track[k].image_id);
      EXPECT_EQ(p.track[k].point2D_idx, other.track[k].point2D_idx);
    }
  }
}

inline void ExpectRigsEqual(const Rig& a, const Rig& b, double quat_tol = 1e-15) {
  ASSERT_EQ(a.size(), b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].name, b[i].name);
    EXPECT_EQ(a[i].camera.model(), b[i].camera.model()) << a[i].name;
    EXPECT_EQ(a[i].camera.width(), b[i].camera.width()) << a[i].name;
    EXPECT_EQ(a[i].camera.height(), b[i].camera.height()) << a[i].name;
    EXPECT_EQ(a[i].camera.params(), b[i].camera.params()) << a[i].name;
    EXPECT_THAT(
        Eigen::Vector4d(a[i].cam_from_world.rotation.coeffs()),
        MatrixNear(Eigen::Vector4d(b[i].cam_from_world.rotation.coeffs()), quat_tol))
        << a[i].name;
    EXPECT_EQ(a[i].cam_from_world.translation, b[i].cam_from_world.translation)
        << a[i].name;
  }
}

}  // namespace handlabel::testing
