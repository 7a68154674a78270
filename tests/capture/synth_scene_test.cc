#include "capture/synth_scene.h"

#include <gtest/gtest.h>

#include <map>

#include "capture/rig_presets.h"
#include "capture/synth_background.h"
#include "capture/synth_detections.h"
#include "capture/synth_view.h"
#include "core/errors.h"
#include "hand/capsule_hand.h"
#include "tests/reference_values.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::TestRng;

struct SceneFixture {
  HandModel model = MakeCapsuleHand(HandSide::kRight);
  HandAnatomy anatomy = ComputeHandAnatomy(model);
  HandLimits limits = DefaultHandLimits();
  Rig rig = MakePresetRig(RigPresetOptions(), 0);
};

TEST(SynthScene, PosesStayWithinTheLimitsAndEveryKindOccurs) {
  SceneFixture s;
  SynthSceneOptions o;
  std::map<std::string, int> kinds;
  for (int i = 0; i < 120; ++i) {
    const SynthScene scene =
        SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng());
    ++kinds[scene.pose_kind];
    HandPoseVector angles;
    HandAnatomicalAngles(s.anatomy, scene.params.hand_pose.data(), angles.data());
    EXPECT_LT(MaxLimitViolationDeg(s.limits, angles), 0.5) << scene.pose_kind;
    EXPECT_LE(scene.params.betas.cwiseAbs().maxCoeff(), 2.5);
  }
  for (const std::string& k : SynthPoseKindNames()) EXPECT_GT(kinds[k], 0) << k;
}

TEST(SynthScene, MostCamerasSeeTheWholeHand) {
  SceneFixture s;
  SynthSceneOptions o;
  int total = 0;
  const int n = 30;
  for (int i = 0; i < n; ++i) {
    const SynthScene scene =
        SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng());
    total += scene.cameras_seeing_hand;
    // cameras_seeing_hand is what the posed keypoints say.
    int seen = 0;
    for (const RigCamera& cam : s.rig.cameras()) {
      bool all = true;
      for (int k = 0; k < kNumHandKeypoints; ++k) {
        Eigen::Vector2d uv;
        all = all && cam.ProjectWorld(scene.hand.keypoints.row(k).transpose(), &uv) &&
              cam.camera.InImage(uv, 2.0);
      }
      seen += all;
    }
    EXPECT_EQ(seen, scene.cameras_seeing_hand);
  }
  EXPECT_GT(static_cast<double>(total) / n, 7.0) << "of 8 DexYCB-like cameras";
}

TEST(SynthScene, ObjectsAreHeldNearTheHand) {
  SceneFixture s;
  SynthSceneOptions o;
  o.objects = true;
  o.max_objects = 3;
  for (int i = 0; i < 20; ++i) {
    const SynthScene scene =
        SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng());
    ASSERT_GE(scene.objects.size(), 1u);
    ASSERT_LE(scene.objects.size(), 3u);
    const Eigen::Vector3d palm = scene.hand.keypoints.row(9).transpose();
    for (const SynthObject& obj : scene.objects) {
      EXPECT_LT((obj.world_from_object.translation - palm).norm(), 0.25) << obj.kind;
    }
  }
}

TEST(SynthScene, ObjectProbabilityMixesEmptyAndObjectFrames) {
  SceneFixture s;
  SynthSceneOptions o;
  o.objects = true;
  o.object_probability = 0.6;
  int with_objects = 0;
  const int n = 100;
  for (int i = 0; i < n; ++i) {
    with_objects += !SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng())
                         .objects.empty();
  }
  // Binomial(100, 0.6): mean 60, sd 4.9; 4 sd either side.
  EXPECT_GT(with_objects, 40);
  EXPECT_LT(with_objects, 80);
  o.object_probability = 1.5;
  EXPECT_THROW(o.Check("test"), InputError);
}

// A scene's values pooled by kind, so that each tolerance meets values of one scale.
struct SceneValues {
  std::vector<double> geometry;    // parameters, points and normals
  std::vector<double> appearance;  // colours in [0, 1], texture coordinates, lights
  std::vector<double> textures;    // 8-bit texels
  std::vector<int> faces;
};

void AddMesh(const RenderMesh& m, SceneValues* v) {
  testing::AppendValues(m.vertices, &v->geometry);
  testing::AppendValues(m.normals, &v->geometry);
  testing::AppendValues(m.colors, &v->appearance);
  testing::AppendValues(m.color, &v->appearance);
  testing::AppendValues(m.uvs, &v->appearance);
  v->faces.insert(v->faces.end(), m.faces.data(), m.faces.data() + m.faces.size());
  if (m.texture) {
    v->faces.push_back(m.texture->width);
    v->faces.push_back(m.texture->height);
    testing::AppendValues(m.texture->data, &v->textures);
  }
}

void AddScene(const SynthScene& scene, const std::string& at,
              testing::ReferenceValues* values) {
  values->Exact(at + ".side", static_cast<int>(scene.side));
  values->Exact(at + ".pose_kind", scene.pose_kind);
  values->Exact(at + ".cameras_seeing_hand", scene.cameras_seeing_hand);
  SceneValues v;
  const HandParams& p = scene.params;
  testing::AppendValues(p.global_orient, &v.geometry);
  testing::AppendValues(p.hand_pose, &v.geometry);
  testing::AppendValues(p.betas, &v.geometry);
  testing::AppendValues(p.transl, &v.geometry);
  testing::AppendValues(scene.hand.vertices, &v.geometry);
  testing::AppendValues(scene.hand.joints, &v.geometry);
  testing::AppendValues(scene.hand.keypoints, &v.geometry);
  AddMesh(scene.hand_render, &v);
  testing::AppendValues(scene.skin, &v.appearance);
  testing::AppendValues(scene.lighting.ambient, &v.appearance);
  for (const DirectionalLight& light : scene.lighting.lights) {
    testing::AppendValues(light.direction_in_world, &v.appearance);
    testing::AppendValues(light.color, &v.appearance);
  }
  std::string kinds;
  for (const SynthObject& b : scene.objects) {
    kinds += b.kind + "/" + std::to_string(b.texture_kind) + " ";
    testing::AppendValues(b.size, &v.geometry);
    testing::AppendValues(b.world_from_object, &v.geometry);
    testing::AppendValues(b.color, &v.appearance);
    AddMesh(b.mesh, &v);
  }
  values->Exact(at + ".objects", kinds).Exact(at + ".faces", v.faces);
  values->Near(at + ".geometry", v.geometry).Near(at + ".appearance", v.appearance);
  values->Near(at + ".textures", v.textures);
}

// A run of scenes (every pose kind, objects on and off).
testing::ReferenceValues SynthSceneValues() {
  SceneFixture s;
  testing::ReferenceValues values("synth_scene_run");
  for (bool objects : {true, false}) {
    SynthSceneOptions o;
    o.objects = objects;
    std::mt19937_64 rng(objects ? 21 : 22);
    for (int i = 0; i < 25; ++i) {
      AddScene(SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, rng),
               (objects ? "objects" : "empty") + std::to_string(i), &values);
    }
    values.Exact(objects ? "objects.next_draw" : "empty.next_draw",
                 static_cast<int64_t>(rng()));
  }
  return values;
}

// The same bits when sampled twice, and tests/data/reference/synth_scene_run.txt within
// 1e-9 relative (poses and meshes go through libm's sin/cos/exp, whose variants differ
// in the last bits between CPUs; kinds, faces, counts and the generator's state after
// the run are compared exactly).
TEST(SynthScene, SameRngKeepsItsScenes) {
  const testing::ReferenceValues first = SynthSceneValues();
  EXPECT_EQ(first.Bits(), SynthSceneValues().Bits());
  EXPECT_TRUE(first.Compare(1e-12, 1e-9));
}

// A run of backgrounds (every base, bands, shapes and noise).
testing::ReferenceValues SynthBackgroundValues() {
  std::mt19937_64 rng(5);
  testing::ReferenceValues values("synth_background_run");
  BackgroundOptions o;
  o.max_noise = 12.0;
  for (int i = 0; i < 16; ++i) {
    const ImageU8 background = MakeBackground(97, 61, o, rng);
    values.Near("background" + std::to_string(i),
                std::vector<double>(background.data.begin(), background.data.end()));
  }
  values.Exact("next_draw", static_cast<int64_t>(rng()));
  return values;
}

// The same pixels when drawn twice, and tests/data/reference/synth_background_run.txt:
// the pixels' sums within 1e-6 of the sum of |pixel| (one pixel rounded the other way
// by a libm variant moves a sum by 1 in about 1.5e6), the generator's state exactly.
TEST(SynthBackground, SameRngKeepsItsPixels) {
  const testing::ReferenceValues first = SynthBackgroundValues();
  EXPECT_EQ(first.Bits(), SynthBackgroundValues().Bits());
  EXPECT_TRUE(first.Compare(0, 1e-6));
}

TEST(SynthView, OccludedAndOutOfFrameKeypointsAreMarked) {
  SceneFixture s;
  SynthSceneOptions o;
  o.objects = true;
  SynthViewOptions vo;
  vo.background.clutter = false;
  int occluded = 0, visible = 0;
  for (int i = 0; i < 10; ++i) {
    const SynthScene scene =
        SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng());
    const PixelRays rays(s.rig[0].camera);
    std::mt19937_64 bg(1);
    const SynthView view = RenderSynthView(scene, s.rig[0], rays, vo, bg);
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      occluded += view.visibility[k] == kOccluded;
      visible += view.visibility[k] == kVisible;
    }
    EXPECT_LE(view.hand_pixels, view.hand_pixels_unoccluded);
  }
  EXPECT_GT(occluded, 5);
  EXPECT_GT(visible, 50);

  // A hand far outside every view is out of frame.
  SynthScene scene = SampleSynthScene(s.model, s.anatomy, s.limits, s.rig, o, TestRng());
  for (Eigen::Index r = 0; r < scene.hand.keypoints.rows(); ++r)
    scene.hand.keypoints(r, 2) += 50;
  scene.hand_render.vertices.col(2).array() += 50;
  scene.objects.clear();
  const PixelRays rays(s.rig[0].camera);
  std::mt19937_64 bg(1);
  const SynthView view = RenderSynthView(scene, s.rig[0], rays, vo, bg);
  EXPECT_EQ(view.status, "out_of_frame");
  EXPECT_EQ(view.hand_pixels, 0);
  for (int v : view.visibility) EXPECT_EQ(v, kOutOfFrame);
}

TEST(SynthDetections, NoiseFreeDetectionsEqualTheGroundTruthAndNoiseHasItsSigma) {
  SceneFixture s;
  SynthViewOptions vo;
  vo.background.clutter = false;
  const SynthScene scene = SampleSynthScene(s.model, s.anatomy, s.limits, s.rig,
                                            SynthSceneOptions(), TestRng());
  const PixelRays rays(s.rig[0].camera);
  std::mt19937_64 bg(1);
  const SynthView view = RenderSynthView(scene, s.rig[0], rays, vo, bg);
  DetectionNoiseOptions exact;
  exact.keypoint_sigma_px = 0;
  exact.outlier_rate = exact.dropout_rate = exact.occluded_dropout_rate = 0;
  exact.mask_morph_radius = exact.mask_blobs = 0;
  const ViewDetections clean = SimulateDetections(view, exact, TestRng());
  EXPECT_EQ(clean.mask.data, view.hand_mask.data);
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    if (view.visibility[k] == kOutOfFrame) continue;
    EXPECT_EQ(clean.keypoints.uv_px(k, 0), view.keypoints(k, 0));
    EXPECT_GT(clean.keypoints.confidence[k], 0.19);
  }
  // Noise: the spread of visible-keypoint errors is sigma.
  DetectionNoiseOptions noisy = exact;
  noisy.keypoint_sigma_px = 3.0;
  double sum2 = 0;
  int n = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const ViewDetections d = SimulateDetections(view, noisy, TestRng());
    for (int k = 0; k < kNumHandKeypoints; ++k) {
      if (view.visibility[k] != kVisible) continue;
      sum2 += (d.keypoints.uv_px.row(k) - view.keypoints.row(k)).squaredNorm() / 2;
      ++n;
    }
  }
  ASSERT_GT(n, 500);
  EXPECT_NEAR(std::sqrt(sum2 / n), 3.0, 0.2);
  // Dropouts: everything missing at rate 1.
  DetectionNoiseOptions drop = exact;
  drop.dropout_rate = drop.occluded_dropout_rate = 1.0;
  const ViewDetections none = SimulateDetections(view, drop, TestRng());
  for (int k = 0; k < kNumHandKeypoints; ++k) {
    EXPECT_EQ(none.keypoints.confidence[k], 0.0);
    EXPECT_TRUE(std::isnan(none.keypoints.uv_px(k, 0)));
  }
}

}  // namespace
}  // namespace handlabel
