#include "capture/synth_capture.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <random>

#include "capture/capture_reader.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "hand/hand_model_io.h"
#include "image/mesh_primitives.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

namespace fs = std::filesystem;
using testing::ScratchDir;

SynthCaptureOptions SmallOptions() {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.num_frames = 3;
  o.seed = 11;
  o.scene.objects = true;
  o.write_depth = true;
  o.num_threads = 1;
  return o;
}

std::map<std::string, std::string> ReadTree(const std::string& root) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file()) continue;
    std::ifstream in(e.path(), std::ios::binary);
    files[fs::relative(e.path(), root).string()] = std::string(
        (std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  }
  return files;
}

// The capture's stored 2D keypoints are its ground truth projected with its rig.
void ExpectKeypointsAreTheProjectedGroundTruth(const CaptureReader& reader) {
  int visible = 0;
  for (int f = 0; f < reader.num_frames(); ++f) {
    const HandGroundTruth gt = reader.ReadGroundTruth(f);
    const std::vector<ViewKeypoints> views = reader.ReadKeypoints(f);
    for (int c = 0; c < reader.num_cameras(); ++c) {
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        Eigen::Vector2d uv;
        ASSERT_TRUE(reader.rig()[c].ProjectWorld(gt.keypoints.row(k).transpose(), &uv));
        EXPECT_NEAR(views[c].keypoints.uv_px(k, 0), uv.x(), 1e-9);
        EXPECT_NEAR(views[c].keypoints.uv_px(k, 1), uv.y(), 1e-9);
        EXPECT_EQ(views[c].visibility[k] == kOutOfFrame,
                  !reader.rig()[c].camera.InImage(uv));
        visible += views[c].visibility[k] == kVisible;
      }
    }
  }
  EXPECT_GT(visible, 100);
}

// A random rig with lens distortion, which the projection must include.
SynthCaptureOptions DistortedRigOptions() {
  SynthCaptureOptions o = SmallOptions();
  o.rig.preset = "random";
  o.rig.distortion = true;
  o.rig.num_cameras = 4;
  return o;
}

TEST(SynthCapture, StoredKeypointsAreTheGroundTruthJointsProjectedWithTheStoredRig) {
  const std::string dir = ScratchDir() + "/cap";
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), DistortedRigOptions(), dir,
                    "builtin:capsule");
  const CaptureReader reader(dir);
  ASSERT_EQ(reader.num_frames(), 3);
  ASSERT_EQ(reader.num_cameras(), 4);
  EXPECT_TRUE(reader.rig()[0].camera.HasDistortion());
  ExpectKeypointsAreTheProjectedGroundTruth(reader);
}

TEST(SynthCapture, SequenceKeypointsAreTheGroundTruthProjectedWithTheStoredRig) {
  const std::string dir = ScratchDir() + "/cap";
  SynthCaptureOptions o = DistortedRigOptions();
  o.sequence.enabled = true;
  o.sequence.fps = 10;  // a coarse rate: 3 frames reach further into the motion
  WriteSynthCapture(MakeCapsuleHand(HandSide::kRight), o, dir, "builtin:capsule");
  ExpectKeypointsAreTheProjectedGroundTruth(CaptureReader(dir));
}

// The capsule hand (no file needed) and the shipped open hand.
class SynthCaptureModels : public ::testing::TestWithParam<std::string> {
 protected:
  HandModel Model() const {
    return GetParam() == "capsule" ? MakeCapsuleHand(HandSide::kRight)
                                   : LoadHandModel(std::string(HANDLABEL_SOURCE_DIR) +
                                                   "/models/" + GetParam());
  }
};

// Re-renders hand and objects separately from the stored ground truth; the stored mask
// must be the pixels where the hand is drawn and no object is nearer.
void ExpectMasksAreTheHandPixelsInFrontOfTheObjects(const HandModel& model,
                                                    const CaptureReader& reader) {
  int hidden_by_object = 0, hand_pixels = 0;
  for (int f = 0; f < reader.num_frames(); ++f) {
    const HandGroundTruth gt = reader.ReadGroundTruth(f);
    RenderMesh hand;
    hand.vertices = gt.vertices;
    hand.faces = model.faces;
    std::vector<RenderMesh> objects;
    for (const ObjectGroundTruth& og : gt.objects) {
      objects.push_back(MakeObjectMesh(og.kind, og.size));
      TransformMesh(og.world_from_object, &objects.back());
    }
    ASSERT_FALSE(objects.empty());
    for (int c = 0; c < reader.num_cameras(); ++c) {
      const RigCamera& cam = reader.rig()[c];
      const PixelRays rays(cam.camera);
      VisibilityBuffer hand_only, objects_only;
      hand_only.Reset(rays.width(), rays.height());
      objects_only.Reset(rays.width(), rays.height());
      RasterizeMesh(hand, 0, cam.cam_from_world, rays, &hand_only);
      for (size_t i = 0; i < objects.size(); ++i) {
        RasterizeMesh(objects[i], static_cast<int>(i + 1), cam.cam_from_world, rays,
                      &objects_only);
      }
      const ImageU8 mask = reader.ReadMask(f, c);
      const ImageU8 object_mask = reader.ReadObjectMask(f, c);
      for (size_t i = 0; i < mask.data.size(); ++i) {
        const bool hand_drawn = hand_only.mesh_id[i] == 0;
        const bool object_nearer =
            objects_only.mesh_id[i] > 0 && objects_only.depth[i] < hand_only.depth[i];
        ASSERT_EQ(mask.data[i] == 255, hand_drawn && !object_nearer)
            << "frame " << f << " camera " << c << " pixel " << i;
        EXPECT_EQ(object_mask.data[i],
                  object_nearer || (!hand_drawn && objects_only.mesh_id[i] > 0)
                      ? objects_only.mesh_id[i]
                      : 0);
        hand_pixels += mask.data[i] == 255;
        hidden_by_object += hand_drawn && object_nearer;
      }
    }
  }
  EXPECT_GT(hand_pixels, 1000);
  EXPECT_GT(hidden_by_object, 20) << "objects should hide some of the hand";
}

TEST_P(SynthCaptureModels, MaskIsExactlyTheHandPixelsInFrontOfTheObjects) {
  const std::string dir = ScratchDir() + "/cap";
  SynthCaptureOptions o = SmallOptions();
  o.scene.max_objects = 3;
  const HandModel model = Model();
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  ExpectMasksAreTheHandPixelsInFrontOfTheObjects(model, CaptureReader(dir));
}

TEST_P(SynthCaptureModels, SequenceMaskIsExactlyTheHandPixelsInFrontOfTheObjects) {
  const std::string dir = ScratchDir() + "/cap";
  SynthCaptureOptions o = SmallOptions();
  o.scene.max_objects = 3;
  o.sequence.enabled = true;
  o.sequence.fps = 2;  // frames 0, 1, 2 at 0, 0.5 and 1 s: reaching, then grasping
  const HandModel model = Model();
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  ExpectMasksAreTheHandPixelsInFrontOfTheObjects(model, CaptureReader(dir));
}

INSTANTIATE_TEST_SUITE_P(Models, SynthCaptureModels,
                         ::testing::Values("capsule", "open_hand_right.npz"),
                         [](const auto& info) {
                           return info.param == "capsule" ? std::string("Capsule")
                                                          : std::string("OpenHand");
                         });

// Distance from p to triangle abc (Ericson, closest point on triangle).
double PointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                             const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return (p - a).norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return (p - b).norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return (p - (a + d1 / (d1 - d3) * ab)).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return (p - c).norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return (p - (a + d2 / (d2 - d6) * ac)).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
    return (p - (b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b))).norm();
  }
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * vb * denom + ac * vc * denom)).norm();
}

TEST(SynthCapture, DepthOfHandPixelsLiesOnTheGroundTruthMesh) {
  const std::string dir = ScratchDir() + "/cap";
  SynthCaptureOptions o = SmallOptions();
  o.num_frames = 1;
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  const CaptureReader reader(dir);
  const HandGroundTruth gt = reader.ReadGroundTruth(0);
  int checked = 0;
  for (int c = 0; c < reader.num_cameras(); ++c) {
    const RigCamera& cam = reader.rig()[c];
    const ImageF depth = reader.ReadDepth(0, c);
    const ImageU8 mask = reader.ReadMask(0, c);
    const Rigid3 world_from_cam = cam.cam_from_world.Inverse();
    for (int y = 0; y < mask.height; y += 2) {
      for (int x = 0; x < mask.width; x += 2) {
        if (mask.at(x, y) == 0) continue;
        const double z = depth.at(x, y);
        ASSERT_GT(z, 0.1);
        const Eigen::Vector3d p =
            world_from_cam * (cam.camera.Unproject(Eigen::Vector2d(x, y)) * z);
        double best = 1e9;
        for (int f = 0; f < model.num_faces(); ++f) {
          best = std::min(best, PointTriangleDistance(
                                    p, gt.vertices.row(model.faces(f, 0)).transpose(),
                                    gt.vertices.row(model.faces(f, 1)).transpose(),
                                    gt.vertices.row(model.faces(f, 2)).transpose()));
        }
        // 16-bit depth in 0.1 mm steps: at most 0.05 mm off along the ray.
        EXPECT_LT(best, 6e-5) << "camera " << c << " pixel " << x << "," << y;
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100);
}

TEST(SynthCapture, ByteIdenticalForAnyThreadCountAndSeedSensitive) {
  const std::string root = ScratchDir();
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  SynthCaptureOptions o = SmallOptions();
  o.num_frames = 4;
  o.num_threads = 1;
  WriteSynthCapture(model, o, root + "/one", "builtin:capsule");
  o.num_threads = 2;
  WriteSynthCapture(model, o, root + "/two", "builtin:capsule");
  const auto one = ReadTree(root + "/one");
  const auto two = ReadTree(root + "/two");
  ASSERT_GT(one.size(), 4 * 8 * 3u);
  EXPECT_EQ(one.size(), two.size());
  for (const auto& [name, bytes] : one) {
    ASSERT_TRUE(two.count(name)) << name;
    EXPECT_TRUE(two.at(name) == bytes) << name << " differs";
  }
  // Another seed: different scenes (parameters and pixels).
  o.seed = 12;
  WriteSynthCapture(model, o, root + "/other", "builtin:capsule");
  const CaptureReader a(root + "/one"), b(root + "/other");
  for (int f = 0; f < 4; ++f) {
    EXPECT_GT(
        (a.ReadGroundTruth(f).params.hand_pose - b.ReadGroundTruth(f).params.hand_pose)
            .norm(),
        1e-3);
    EXPECT_NE(a.ReadImage(f, 0).data, b.ReadImage(f, 0).data);
  }
  // Frames of one capture differ from each other too.
  EXPECT_NE(a.ReadGroundTruth(0).params.transl, a.ReadGroundTruth(1).params.transl);
}

TEST(SynthCapture, ReaderReturnsExactlyWhatTheGeneratorMade) {
  const std::string dir = ScratchDir() + "/cap";
  const HandModel model = MakeCapsuleHand(HandSide::kLeft);
  SynthCaptureOptions o = SmallOptions();
  o.rig.preset = "ho3d";
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  const SynthGenerator generator(model, MakePresetRig(o.rig, o.seed), o);
  const CaptureReader reader(dir);
  EXPECT_EQ(reader.manifest().hand_side, "left");
  EXPECT_EQ(reader.manifest().generator["seed"], 11);
  ASSERT_EQ(reader.num_cameras(), 5);
  for (int c = 0; c < 5; ++c) {
    EXPECT_EQ(reader.rig()[c].name, generator.rig()[c].name);
    EXPECT_EQ(reader.rig()[c].camera.params(), generator.rig()[c].camera.params());
    EXPECT_THAT(reader.rig()[c].cam_from_world,
                testing::Rigid3Near(generator.rig()[c].cam_from_world, 1e-12, 1e-12));
  }
  for (int f = 0; f < reader.num_frames(); ++f) {
    const SynthFrame frame = generator.Generate(f);
    const HandGroundTruth gt = reader.ReadGroundTruth(f);
    EXPECT_EQ(gt.pose_kind, frame.scene.pose_kind);
    EXPECT_EQ(gt.side, "left");
    EXPECT_EQ(gt.params.hand_pose, frame.scene.params.hand_pose);
    EXPECT_EQ(gt.params.global_orient, frame.scene.params.global_orient);
    EXPECT_EQ(gt.params.betas, frame.scene.params.betas);
    EXPECT_EQ(gt.params.transl, frame.scene.params.transl);
    EXPECT_EQ(gt.vertices, frame.scene.hand.vertices);
    EXPECT_EQ(gt.keypoints, frame.scene.hand.keypoints);
    EXPECT_EQ(gt.joints, frame.scene.hand.joints);
    EXPECT_EQ(gt.objects.size(), frame.scene.objects.size());
    const auto det = reader.ReadDetections(f);
    for (int c = 0; c < 5; ++c) {
      EXPECT_EQ(reader.ReadImage(f, c).data, frame.views[c].rgb.data);
      EXPECT_EQ(reader.ReadMask(f, c).data, frame.views[c].hand_mask.data);
      EXPECT_EQ(reader.ReadDetectionMask(f, c).data, frame.detections[c].mask.data);
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        EXPECT_EQ(det[c].keypoints.confidence[k],
                  frame.detections[c].keypoints.confidence[k]);
        if (det[c].keypoints.confidence[k] > 0) {
          EXPECT_EQ(det[c].keypoints.uv_px(k, 0),
                    frame.detections[c].keypoints.uv_px(k, 0));
        } else {
          EXPECT_TRUE(std::isnan(det[c].keypoints.uv_px(k, 0)));
        }
      }
    }
  }
}

TEST(SynthCapture, RefusesToOverwriteACaptureUnlessAsked) {
  const std::string dir = ScratchDir() + "/cap";
  SynthCaptureOptions o = SmallOptions();
  o.num_frames = 1;
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  WriteSynthCapture(model, o, dir, "builtin:capsule");
  EXPECT_THROW(WriteSynthCapture(model, o, dir, "builtin:capsule"), InputError);
  EXPECT_NO_THROW(WriteSynthCapture(model, o, dir, "builtin:capsule", true));
}

TEST(SynthCapture, BadOptionsNameTheField) {
  SynthCaptureOptions o = SmallOptions();
  o.rig.preset = "kinect";
  try {
    o.Check("test");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "preset");
  }
  o = SmallOptions();
  o.num_frames = 0;
  EXPECT_THROW(o.Check("test"), InputError);
  o = SmallOptions();
  o.detections.outlier_rate = 1.5;
  EXPECT_THROW(o.Check("test"), InputError);
}

// Photographs behind the render: every pixel nothing was drawn on is the camera's own
// photograph, the rendered ones are not, and the realistic look leaves its table out.
TEST(SynthCapture, PhotoBackgroundsShowWhereNothingIsDrawn) {
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  SynthCaptureOptions o = SmallOptions();
  const Rig rig = MakePresetRig(o.rig, o.seed);
  auto photos = std::make_shared<std::vector<ImageU8>>();
  std::mt19937_64 rng(5);
  for (size_t c = 0; c < rig.size(); ++c) {
    ImageU8 photo(rig[c].camera.width(), rig[c].camera.height(), 3);
    for (uint8_t& v : photo.data) v = static_cast<uint8_t>(rng() % 256);
    photos->push_back(photo);
  }
  o.view.photo_backgrounds = photos;
  const SynthFrame frame = SynthGenerator(model, rig, o).Generate(1);
  int drawn = 0, photo_pixels = 0;
  for (size_t c = 0; c < rig.size(); ++c) {
    const SynthView& view = frame.views[c];
    for (int y = 0; y < view.rgb.height; ++y) {
      for (int x = 0; x < view.rgb.width; ++x) {
        const bool nothing_drawn = view.depth.at(x, y) == 0;
        const bool same = view.rgb.at(x, y, 0) == (*photos)[c].at(x, y, 0) &&
                          view.rgb.at(x, y, 1) == (*photos)[c].at(x, y, 1) &&
                          view.rgb.at(x, y, 2) == (*photos)[c].at(x, y, 2);
        if (nothing_drawn) {
          ASSERT_TRUE(same) << "camera " << c << " pixel " << x << ", " << y;
          ++photo_pixels;
        } else {
          drawn += !same;
        }
      }
    }
  }
  EXPECT_GT(drawn, 100);
  EXPECT_GT(photo_pixels, drawn);

  // The realistic look: no table, and its blur and noise leave the photograph alone
  // away from the render's edges.
  o.view.appearance = SynthAppearance::kRealistic;
  const SynthGenerator realistic(model, rig, o);
  EXPECT_FALSE(realistic.options().view.realistic.table);
  const SynthFrame look = realistic.Generate(1);
  int untouched = 0, changed = 0;
  for (size_t c = 0; c < rig.size(); ++c) {
    const SynthView& view = look.views[c];
    const auto drawn_near = [&](int x, int y) {
      for (int v = std::max(0, y - 3); v <= std::min(view.rgb.height - 1, y + 3); ++v) {
        for (int u = std::max(0, x - 3); u <= std::min(view.rgb.width - 1, x + 3); ++u) {
          if (view.depth.at(u, v) > 0) return true;
        }
      }
      return false;
    };
    for (int y = 0; y < view.rgb.height; ++y) {
      for (int x = 0; x < view.rgb.width; ++x) {
        if (drawn_near(x, y)) continue;
        const bool same = view.rgb.at(x, y, 0) == (*photos)[c].at(x, y, 0) &&
                          view.rgb.at(x, y, 1) == (*photos)[c].at(x, y, 1) &&
                          view.rgb.at(x, y, 2) == (*photos)[c].at(x, y, 2);
        (same ? untouched : changed) += 1;
      }
    }
  }
  EXPECT_EQ(changed, 0);
  EXPECT_GT(untouched, 1000);

  (*photos)[2] = ImageU8(10, 10, 3);
  try {
    SynthGenerator(model, rig, o);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(e.field(), "view.photo_backgrounds[2]");
  }
  photos->pop_back();
  EXPECT_THROW(SynthGenerator(model, rig, o), InputError);
}

}  // namespace
}  // namespace handlabel
