#include "capture/synth_sequence.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <iostream>
#include <string>
#include <vector>

#include "capture/capture_reader.h"
#include "capture/rig_presets.h"
#include "capture/synth_capture.h"
#include "core/errors.h"
#include "core/random.h"
#include "hand/capsule_hand.h"
#include "hand/hand_model_io.h"
#include "hand/metrics.h"
#include "tests/test_util.h"

namespace handlabel {
namespace {

using testing::FilesUnder;
using testing::ScratchDir;

SynthCaptureOptions SequenceOptions() {
  SynthCaptureOptions o;
  o.rig.preset = "dexycb";
  o.rig.width = 160;
  o.rig.height = 120;
  o.scene.objects = true;
  o.sequence.enabled = true;
  o.seed = 45;
  o.num_threads = 1;
  return o;
}

// Scenes of a sequence without rendering, through the open hand.
class SequenceScenes {
 public:
  explicit SequenceScenes(const SynthCaptureOptions& options)
      : model_(LoadHandModel(std::string(HANDLABEL_SOURCE_DIR) +
                             "/models/open_hand_right.npz")),
        anatomy_(ComputeHandAnatomy(model_)),
        limits_(DefaultHandLimits()),
        options_(options),
        rig_(MakePresetRig(options.rig, options.seed)) {}

  SynthScene Frame(int f) const {
    return SampleSynthSequenceScene(model_, anatomy_, limits_, rig_, options_.scene,
                                    options_.sequence, options_.seed,
                                    f / options_.sequence.fps);
  }
  // Today's independent frames, drawn as SynthGenerator draws them.
  SynthScene IndependentFrame(int f) const {
    std::mt19937_64 rng(MixSeed(options_.seed, f, 1));
    return SampleSynthScene(model_, anatomy_, limits_, rig_, options_.scene, rng);
  }

 private:
  HandModel model_;
  HandAnatomy anatomy_;
  HandLimits limits_;
  SynthCaptureOptions options_;
  Rig rig_;
};

// The largest |a| of any keypoint over the triples of consecutive frames.
double LargestAcceleration(const std::vector<MotionFrame>& frames) {
  double largest = 0;
  for (size_t i = 1; i + 1 < frames.size(); ++i) {
    const Points3d a =
        frames[i - 1].predicted - 2 * frames[i].predicted + frames[i + 1].predicted;
    largest = std::max(largest, a.rowwise().norm().maxCoeff());
  }
  return largest;
}

TEST(SynthSequence, FramesMoveSmoothlyWhereIndependentFramesJump) {
  SynthCaptureOptions o = SequenceOptions();
  const SequenceScenes scenes(o);
  const int frames = 200;  // two grasp cycles and a bit at 30 fps
  std::vector<MotionFrame> sequence, independent;
  std::vector<std::string> phases;
  double largest_step = 0;
  for (int f = 0; f < frames; ++f) {
    const SynthScene scene = scenes.Frame(f);
    if (phases.empty() || phases.back() != scene.pose_kind)
      phases.push_back(scene.pose_kind);
    if (f > 0) {
      largest_step = std::max(
          largest_step,
          (scene.hand.keypoints - sequence.back().predicted).rowwise().norm().maxCoeff());
    }
    sequence.push_back({f, scene.hand.keypoints, {}});
    independent.push_back({f, scenes.IndependentFrame(f).hand.keypoints, {}});
  }
  const MotionMetrics smooth = ComputeMotionMetrics(sequence);
  const MotionMetrics jumps = ComputeMotionMetrics(independent);
  std::cout << "keypoint acceleration (mm/frame^2, 30 fps): sequence mean "
            << 1000 * smooth.jitter << " max " << 1000 * LargestAcceleration(sequence)
            << ", independent frames mean " << 1000 * jumps.jitter << "; largest step "
            << 1000 * largest_step << " mm\n";
  EXPECT_EQ(smooth.triples, frames - 2);
  // At most 2.5 cm per frame (75 cm/s) for any keypoint, fingertips included.
  EXPECT_LT(largest_step, 0.025);
  EXPECT_LT(LargestAcceleration(sequence), 0.006);
  EXPECT_LT(20 * smooth.jitter, jumps.jitter);
  const std::vector<std::string> cycle = {"reach", "grasp", "carry",   "release", "reach",
                                          "grasp", "carry", "release", "reach"};
  EXPECT_EQ(phases, cycle);
}

TEST(SynthSequence, FrameRateChangesTheSamplingNotTheMotion) {
  SynthCaptureOptions at30 = SequenceOptions();
  SynthCaptureOptions at60 = at30;
  at60.sequence.fps = 60;
  const SequenceScenes scenes30(at30), scenes60(at60);
  for (int k : {0, 7, 29, 46, 90, 131}) {
    const SynthScene a = scenes30.Frame(k), b = scenes60.Frame(2 * k);
    EXPECT_EQ(a.pose_kind, b.pose_kind);
    EXPECT_THAT(b.hand.keypoints, testing::MatrixNear(a.hand.keypoints, 1e-9));
    EXPECT_THAT(b.hand.vertices, testing::MatrixNear(a.hand.vertices, 1e-9));
    ASSERT_EQ(a.objects.size(), b.objects.size());
    for (size_t i = 0; i < a.objects.size(); ++i) {
      EXPECT_THAT(b.objects[i].world_from_object,
                  testing::Rigid3Near(a.objects[i].world_from_object, 1e-9, 1e-9));
    }
    // The frame in between lies between its neighbours.
    const SynthScene mid = scenes60.Frame(2 * k + 1), next = scenes30.Frame(k + 1);
    const double half_way =
        (mid.hand.keypoints - 0.5 * (a.hand.keypoints + next.hand.keypoints))
            .rowwise()
            .norm()
            .maxCoeff();
    EXPECT_LT(half_way, 0.002) << "frame " << 2 * k + 1 << " at 60 fps";
  }
}

// The hand's root rotation (global_orient) as a matrix.
Eigen::Matrix3d RootRotation(const HandParams& params) {
  const double angle = params.global_orient.norm();
  return angle > 0
             ? Eigen::AngleAxisd(angle, params.global_orient / angle).toRotationMatrix()
             : Eigen::Matrix3d::Identity();
}

// The held object's centre as distances to a few keypoints and its rotation relative
// to the hand's root: constant while it is carried.
Eigen::VectorXd HeldInHand(const SynthScene& scene) {
  const SynthObject& held = scene.objects.at(0);
  Eigen::VectorXd v(6 + 9);
  int i = 0;
  for (int k : {0, 4, 5, 8, 9, 17}) {
    v[i++] =
        (held.world_from_object.translation - scene.hand.keypoints.row(k).transpose())
            .norm();
  }
  const Eigen::Matrix3d relative = RootRotation(scene.params).transpose() *
                                   held.world_from_object.rotation.toRotationMatrix();
  for (int e = 0; e < 9; ++e) v[i++] = relative(e);
  return v;
}

TEST(SynthSequence, HeldObjectMovesWithTheHandOnlyWhileCarried) {
  SynthCaptureOptions o = SequenceOptions();
  o.scene.max_objects = 2;
  const SequenceScenes scenes(o);
  std::string phase;
  SynthScene first_of_phase;
  double carried_furthest = 0;
  int carried_frames = 0;
  for (int f = 0; f < 180; ++f) {
    const SynthScene scene = scenes.Frame(f);
    ASSERT_FALSE(scene.objects.empty());
    // From the second cycle on, the object put down before lies where it was put.
    if (f >= 90) {
      EXPECT_EQ(scene.objects.size(), 2u) << "frame " << f;
    }
    if (scene.pose_kind != phase) {
      phase = scene.pose_kind;
      first_of_phase = scene;
      continue;
    }
    const Rigid3& now = scene.objects[0].world_from_object;
    const Rigid3& then = first_of_phase.objects[0].world_from_object;
    if (phase == "carry") {
      EXPECT_THAT(HeldInHand(scene),
                  testing::MatrixNear(HeldInHand(first_of_phase), 1e-9))
          << "frame " << f;
      carried_furthest =
          std::max(carried_furthest, (now.translation - then.translation).norm());
      ++carried_frames;
    } else {
      EXPECT_THAT(now, testing::Rigid3Near(then, 1e-12, 1e-12))
          << phase << " frame " << f << ": only carrying moves the object";
    }
    if (phase == "carry") {
      // Held: the object's surface within 2.5 cm of the closed hand's.
      double nearest = 1e9;
      for (Eigen::Index v = 0; v < scene.objects[0].mesh.vertices.rows(); ++v) {
        nearest = std::min(nearest, (scene.hand.vertices.rowwise() -
                                     scene.objects[0].mesh.vertices.row(v))
                                        .rowwise()
                                        .norm()
                                        .minCoeff());
      }
      EXPECT_LT(nearest, 0.025) << "frame " << f;
    }
  }
  EXPECT_GT(carried_frames, 40);
  EXPECT_GT(carried_furthest, 0.02) << "the carry should move the object";
}

TEST(SynthSequence, SameSeedSameBytesAndAnyFrameMadeAlone) {
  const std::string root = ScratchDir();
  const HandModel model = MakeCapsuleHand(HandSide::kRight);
  SynthCaptureOptions o = SequenceOptions();
  o.num_frames = 6;
  WriteSynthCapture(model, o, root + "/one", "builtin:capsule");
  o.num_threads = 2;
  WriteSynthCapture(model, o, root + "/two", "builtin:capsule");
  const auto one = FilesUnder(root + "/one"), two = FilesUnder(root + "/two");
  ASSERT_GT(one.size(), 6 * 8 * 3u);
  EXPECT_TRUE(one == two) << "the same seed gave other bytes";

  // Frame 4 made by a generator that made nothing before is the file's frame 4.
  const CaptureReader reader(root + "/one");
  EXPECT_EQ(reader.manifest().generator["settings"]["sequence"]["fps"], 30.0);
  const SynthGenerator alone(model, MakePresetRig(o.rig, o.seed), o);
  const SynthFrame frame = alone.Generate(4);
  const HandGroundTruth gt = reader.ReadGroundTruth(4);
  EXPECT_EQ(gt.pose_kind, frame.scene.pose_kind);
  EXPECT_THAT(gt.keypoints, testing::MatrixNear(frame.scene.hand.keypoints, 1e-12));
  EXPECT_THAT(gt.params.transl, testing::MatrixNear(frame.scene.params.transl, 1e-12));
  for (int c = 0; c < reader.num_cameras(); ++c) {
    EXPECT_EQ(reader.ReadMask(4, c).data, frame.views[c].hand_mask.data) << c;
  }
  // The cameras do not move: the background far from the hand is the same in every
  // frame (in the independent frames it is drawn anew).
  EXPECT_EQ(reader.ReadImage(0, 0).at(0, 0, 0), reader.ReadImage(5, 0).at(0, 0, 0));
  EXPECT_EQ(reader.ReadImage(0, 0).at(2, 118, 1), reader.ReadImage(5, 0).at(2, 118, 1));

  // Another seed: another motion.
  o.seed = 46;
  const SynthGenerator other(model, MakePresetRig(o.rig, o.seed), o);
  EXPECT_GT((other.Generate(4).scene.hand.keypoints - frame.scene.hand.keypoints).norm(),
            1e-3);
}

TEST(SynthSequence, IndependentCapturesRecordNoSequence) {
  SynthCaptureOptions o = SequenceOptions();
  EXPECT_TRUE(SynthOptionsToJson(o).contains("sequence"));
  o.sequence.enabled = false;
  EXPECT_FALSE(SynthOptionsToJson(o).contains("sequence"));
}

TEST(SynthSequence, MinimumJerkStartsAndStopsAtRest) {
  EXPECT_EQ(MinimumJerk(0), 0);
  EXPECT_EQ(MinimumJerk(1), 1);
  EXPECT_NEAR(MinimumJerk(0.5), 0.5, 1e-15);
  EXPECT_EQ(MinimumJerk(-1), 0);
  EXPECT_EQ(MinimumJerk(2), 1);
  // Velocity and acceleration vanish at both ends (finite differences).
  const double h = 1e-4;
  for (double u : {0.0, 1.0}) {
    const double v = (MinimumJerk(u + h) - MinimumJerk(u - h)) / (2 * h);
    const double a =
        (MinimumJerk(u + h) - 2 * MinimumJerk(u) + MinimumJerk(u - h)) / (h * h);
    EXPECT_NEAR(v, 0, 1e-6) << u;
    EXPECT_NEAR(a, 0, 1e-2) << u;
  }
  // The bell-shaped speed peaks at 15/8 in the middle.
  EXPECT_NEAR((MinimumJerk(0.5 + h) - MinimumJerk(0.5 - h)) / (2 * h), 1.875, 1e-6);
}

TEST(SynthSequence, BadOptionsNameTheField) {
  SynthCaptureOptions o = SequenceOptions();
  o.sequence.fps = 0;
  EXPECT_THAT(testing::InputErrorOf([&] { o.Check("synth options"); }),
              ::testing::HasSubstr("fps"));
  o = SequenceOptions();
  o.sequence.carry_seconds = -1;
  EXPECT_THAT(testing::InputErrorOf([&] { o.Check("synth options"); }),
              ::testing::HasSubstr("carry_seconds"));
}

}  // namespace
}  // namespace handlabel
